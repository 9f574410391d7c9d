// The method registry (methods/registry.hpp): each method once, found by its
// --method name, and an unknown name refused naming every method; the fluid
// methods run by their job factories, their options read by set_from_text.
#include <gtest/gtest.h>

#include <set>

#include "tempera/engine/error.hpp"
#include "tempera/engine/option_table.hpp"
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

TEST(Registry, TheFluidMethodsRunByTheirJobFactory) {
  for (const char* name : {"lazyfluids", "fluidymation"}) {
    const MethodEntry& m = find_method(name);
    ASSERT_TRUE(m.make_job) << name << " needs its own command again";
    EXPECT_NE(m.options_help.find("[V]"), std::string::npos) << name << ": its switches may stand alone";
    JobConfig config;
    config.exemplar = "nowhere.png";
    config.guides = "nowhere";
    config.frames = {1, 2};
    config.out = "nowhere_out";
    try {  // the options are read before any file
      m.make_job(config, {{"bogus", "1"}});
      FAIL() << name << " took --bogus";
    } catch (const ValueError& e) {
      EXPECT_NE(std::string(e.what()).find("unknown option '--bogus' for --method " + std::string(name)),
                std::string::npos)
          << e.what();
    }
  }
}

namespace {
struct Switches {
  bool rotations = false;
  float lambda = 0.2f;
};
const auto& switches_table() {
  static const auto table = std::make_tuple(field(&Switches::rotations, "rotations", "rotations", "turned copies"),
                                            field(&Switches::lambda, "lambda", "lambda", "coherence", 0.0, 1.0));
  return table;
}
}  // namespace

TEST(Registry, AMethodOptionAloneIsASwitchOnlyForYesNoFields) {
  Switches s;
  EXPECT_TRUE(set_from_text(s, switches_table(), "rotations", ""));
  EXPECT_TRUE(s.rotations);
  EXPECT_TRUE(set_from_text(s, switches_table(), "rotations", "false"));
  EXPECT_FALSE(s.rotations);
  EXPECT_TRUE(set_from_text(s, switches_table(), "lambda", "0.5"));
  EXPECT_FLOAT_EQ(s.lambda, 0.5f);
  EXPECT_THROW(set_from_text(s, switches_table(), "lambda", ""), ValueError);  // "--lambda needs a value"
  EXPECT_FALSE(set_from_text(s, switches_table(), "eta", "3"));                // not this table's
  EXPECT_NE(flags_help<Switches>(switches_table(), true).find("--rotations [V]"), std::string::npos);
  EXPECT_NE(flags_help<Switches>(switches_table()).find("--rotations V"), std::string::npos);
}
