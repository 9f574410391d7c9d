#pragma once
// Light path expressions (Heckbert's notation, thesis §8.3.2) compiled to a
// DFA. Expressions are written light-to-eye ("LDE": light, one diffuse
// bounce, eye); the path tracer builds paths from the eye, so it compiles them
// reversed and feeds events eye-first, one per path vertex.
//
// Events: L emitter (lights, emissive surfaces, world), D diffuse, S glossy or
// specular reflection (G is a synonym), T transmission, E eye.
// Operators: `.` any event but E, `*`, `+`, `?`, `{m}`, `{m,}`, `{m,n}`,
// `[DS]` sets, `[^D]` negated sets (any event but E not listed), `|`
// alternation and parentheses.
#include <cstdint>
#include <string_view>
#include <vector>

namespace tempera {

enum class LpeEvent : std::uint8_t { L, D, S, T, E };
inline constexpr int kLpeEventCount = 5;

// Which end of the path the DFA reads first.
enum class LpeOrder { light_to_eye, eye_to_light };

struct LpeDfa {
  static constexpr int kDead = -1;  // the state no input ever leaves

  LpeOrder order = LpeOrder::light_to_eye;
  int start = 0;
  std::vector<int> next;          // next[state * kLpeEventCount + event], kDead if none
  std::vector<char> accepting;    // per state
  std::vector<char> live;         // per state: some accepting state is reachable

  int step(int state, LpeEvent event) const {
    return state == kDead ? kDead : next[std::size_t(state) * kLpeEventCount + int(event)];
  }
  bool accepts(int state) const { return state != kDead && accepting[std::size_t(state)]; }
  bool alive(int state) const { return state != kDead && live[std::size_t(state)]; }
};

// Parses and compiles `expression`; malformed input throws ValueError naming
// the 0-based position and what was expected there.
LpeDfa compile_lpe(std::string_view expression, LpeOrder order = LpeOrder::light_to_eye);

// Whether the whole event string (letters L D S G T E, always written
// light-to-eye whatever the DFA's order) is matched.
bool lpe_matches(const LpeDfa& dfa, std::string_view events);

// Whether any event string at all is matched (false for e.g. "L[^LDST]E").
bool lpe_can_match(const LpeDfa& dfa);

}  // namespace tempera
