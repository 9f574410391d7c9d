// The method registry (methods/registry.hpp): each method once, found by its
// --method name, and an unknown name refused naming every method.
#include <gtest/gtest.h>

#include <set>

#include "tempera/engine/error.hpp"
#include "tempera/methods/registry.hpp"

using namespace tempera;

TEST(Registry, EachMethodOnceWithAKnownUnit) {
  std::set<std::string> names;
  for (const MethodEntry& m : method_registry()) {
    EXPECT_TRUE(names.insert(m.name).second) << m.name << " is registered twice";
    EXPECT_TRUE(m.unit == "frame" || m.unit == "segment" || m.unit == "chained frame") << m.name << ": " << m.unit;
    EXPECT_EQ(&find_method(m.name), &m);
  }
  EXPECT_EQ(find_method("tcia").unit, "segment");  // the farm plans one task per segment
}

TEST(Registry, AnUnknownMethodNamesEveryOne) {
  try {
    find_method("ebsynth");
    FAIL() << "ebsynth is not a method";
  } catch (const ValueError& e) {
    const std::string text = e.what();
    EXPECT_NE(text.find("unknown --method 'ebsynth'"), std::string::npos) << text;
    for (const MethodEntry& m : method_registry()) EXPECT_NE(text.find(m.name), std::string::npos) << text;
  }
}
