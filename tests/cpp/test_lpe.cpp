#include <gtest/gtest.h>

#include "tempera/engine/error.hpp"
#include "tempera/tracer/lpe.hpp"

using namespace tempera;

namespace {

bool matches(const char* expression, const char* events) {
  const bool forward = lpe_matches(compile_lpe(expression), events);
  // The tracer's eye-first DFA must agree with the light-first one.
  EXPECT_EQ(forward, lpe_matches(compile_lpe(expression, LpeOrder::eye_to_light), events)) << expression;
  return forward;
}

std::string error_of(const char* expression) {
  try {
    compile_lpe(expression);
  } catch (const ValueError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Lpe, AcceptsStylitExpressions) {
  for (const char* e : {"L.*E", "LDE", "LSE", "L.*DDE", "LD{1,2}E", "LS*DE", "LS+DE", "L.*SDE", "LGE", "L[DS]E",
                        "L[^D]E", "L(D|S)E", "LD{2}E", "LD{1,}E", "L(DS)?E"})
    EXPECT_NO_THROW(compile_lpe(e)) << e;
}

TEST(Lpe, ErrorsNamePositionAndExpectation) {
  EXPECT_EQ(error_of("L(DE"), "LPE \"L(DE\": position 4: expected ')'");
  EXPECT_EQ(error_of("LDE)"), "LPE \"LDE)\": position 3: expected end of expression");
  EXPECT_EQ(error_of("LXE"), "LPE \"LXE\": position 1: expected an event, '.', '[' or '('");
  EXPECT_EQ(error_of(""), "LPE \"\": position 0: expected an event, '.', '[' or '('");
  EXPECT_EQ(error_of("L*E"), "");  // L* is fine: the star applies to L
  EXPECT_EQ(error_of("*LE"), "LPE \"*LE\": position 0: expected an event, '.', '[' or '('");
  EXPECT_EQ(error_of("L[DX]E"), "LPE \"L[DX]E\": position 3: expected an event letter or ']'");
  EXPECT_EQ(error_of("L[]E"), "LPE \"L[]E\": position 2: expected an event letter");
  EXPECT_EQ(error_of("LD{E"), "LPE \"LD{E\": position 3: expected a count from 0 to 100");
  EXPECT_EQ(error_of("LD{2,1}E"), "LPE \"LD{2,1}E\": position 5: expected a count from 2 to 100");
  EXPECT_EQ(error_of("LD{2E"), "LPE \"LD{2E\": position 4: expected ',' or '}'");
  EXPECT_EQ(error_of("LD{1,2E"), "LPE \"LD{1,2E\": position 6: expected '}'");
  EXPECT_EQ(error_of("L(D|)E"), "LPE \"L(D|)E\": position 4: expected an event, '.', '[' or '('");
}

TEST(Lpe, OperatorsMatchWholeStrings) {
  EXPECT_TRUE(matches("LDE", "LDE"));
  EXPECT_FALSE(matches("LDE", "LDDE"));
  EXPECT_FALSE(matches("LDE", "LD"));  // whole string, not a prefix
  EXPECT_TRUE(matches("L.E", "LTE"));
  EXPECT_FALSE(matches("L.E", "LEE"));  // `.` is any event but E
  EXPECT_TRUE(matches("LD*E", "LE"));
  EXPECT_TRUE(matches("LD*E", "LDDDE"));
  EXPECT_FALSE(matches("LD+E", "LE"));
  EXPECT_TRUE(matches("LD+E", "LDDE"));
  EXPECT_TRUE(matches("LD?E", "LE"));
  EXPECT_FALSE(matches("LD?E", "LDDE"));
  EXPECT_TRUE(matches("LD{2}E", "LDDE"));
  EXPECT_FALSE(matches("LD{2}E", "LDE"));
  EXPECT_TRUE(matches("LD{2,}E", "LDDDDE"));
  EXPECT_FALSE(matches("LD{2,}E", "LDE"));
  EXPECT_TRUE(matches("L[DS]E", "LSE"));
  EXPECT_FALSE(matches("L[DS]E", "LTE"));
  EXPECT_TRUE(matches("L[^D]E", "LTE"));
  EXPECT_FALSE(matches("L[^D]E", "LDE"));
  EXPECT_TRUE(matches("L(DS|T)E", "LDSE"));
  EXPECT_TRUE(matches("L(DS|T)E", "LTE"));
  EXPECT_FALSE(matches("L(DS|T)E", "LDE"));
  EXPECT_TRUE(matches("LGE", "LSE"));  // G is S
  EXPECT_TRUE(matches("LS*DE", "LSSDE"));
  EXPECT_TRUE(matches("LS+DE", "LSDE"));
  EXPECT_FALSE(matches("LS+DE", "LDE"));
  EXPECT_TRUE(matches("L.*SDE", "LDTSDE"));
  EXPECT_FALSE(matches("L.*SDE", "LSDDE"));
}

TEST(Lpe, BoundedRepetition) {
  EXPECT_TRUE(matches("LD{1,2}E", "LDE"));
  EXPECT_TRUE(matches("LD{1,2}E", "LDDE"));
  EXPECT_FALSE(matches("LD{1,2}E", "LDDDE"));
  EXPECT_FALSE(matches("LD{1,2}E", "LE"));
}

TEST(Lpe, InterreflectionNeedsTwoDiffuse) {
  EXPECT_TRUE(matches("L.*DDE", "LDDE"));
  EXPECT_TRUE(matches("L.*DDE", "LSDDE"));
  EXPECT_FALSE(matches("L.*DDE", "LDE"));
  EXPECT_FALSE(matches("L.*DDE", "LDSE"));
}

TEST(Lpe, DeadExpressions) {
  EXPECT_TRUE(lpe_can_match(compile_lpe("LDE")));
  EXPECT_FALSE(lpe_can_match(compile_lpe("L[^LDST]E")));  // an empty event set
  EXPECT_FALSE(lpe_can_match(compile_lpe("L[^LDST]*[^LDST]E", LpeOrder::eye_to_light)));
  EXPECT_TRUE(lpe_can_match(compile_lpe("LD{0}E")));  // matches LE
  EXPECT_TRUE(matches("LD{0}E", "LE"));
}

TEST(Lpe, UnknownEventLetterInPathIsAnError) {
  EXPECT_THROW(lpe_matches(compile_lpe("LDE"), "LXE"), ValueError);
}
