// Light path expressions: recursive-descent parser -> syntax tree -> Thompson
// NFA -> DFA by subset construction. Expressions are a few characters long,
// so the DFA is tiny and built once per render; tracing only steps through it.
#include "tempera/tracer/lpe.hpp"

#include <algorithm>
#include <map>
#include <memory>
#include <string>

#include "tempera/engine/error.hpp"

namespace tempera {
namespace {

using EventMask = std::uint8_t;  // bit i: LpeEvent(i)
constexpr EventMask bit(LpeEvent e) { return EventMask(1u << int(e)); }
constexpr EventMask kAnyButEye = bit(LpeEvent::L) | bit(LpeEvent::D) | bit(LpeEvent::S) | bit(LpeEvent::T);
constexpr int kMaxCount = 100;  // bound on {m,n}: keeps the NFA small
// Bounds that keep any text cheap to reject: the parser and the NFA build
// recurse once per nesting level, so the depth bounds their stacks; the NFA
// and DFA state counts bound the memory and time of the subset construction.
constexpr std::size_t kMaxLength = 1000;
constexpr int kMaxDepth = 64;        // nested '(' plus stacked repeat operators
constexpr std::size_t kMaxNfaStates = 5000;
constexpr std::size_t kMaxDfaStates = 4096;

bool event_of(char c, LpeEvent& out) {
  switch (c) {
    case 'L': out = LpeEvent::L; return true;
    case 'D': out = LpeEvent::D; return true;
    case 'S':
    case 'G': out = LpeEvent::S; return true;
    case 'T': out = LpeEvent::T; return true;
    case 'E': out = LpeEvent::E; return true;
    default: return false;
  }
}

struct Node {
  enum class Kind { set, concat, alternation, repeat } kind = Kind::set;
  EventMask events = 0;             // set
  std::vector<std::unique_ptr<Node>> children;
  int min = 1, max = 1;             // repeat; max < 0: unbounded
};
using NodePtr = std::unique_ptr<Node>;

NodePtr make(Node::Kind kind) {
  auto node = std::make_unique<Node>();
  node->kind = kind;
  return node;
}

class Parser {
 public:
  explicit Parser(std::string_view text) : text_(text) {}

  NodePtr parse() {
    if (text_.size() > kMaxLength)
      throw ValueError(concat("LPE is ", text_.size(), " characters long; at most ", kMaxLength, " are allowed"));
    NodePtr root = alternation();
    if (pos_ < text_.size()) fail("end of expression");
    return root;
  }

 private:
  [[noreturn]] void fail(std::string_view expected) const {
    throw ValueError(concat("LPE \"", text_, "\": position ", pos_, ": expected ", expected));
  }
  void deeper() {
    if (++depth_ > kMaxDepth)
      throw ValueError(concat("LPE \"", text_.substr(0, 40), text_.size() > 40 ? "..." : "", "\": position ", pos_,
                              ": nested more than ", kMaxDepth, " levels deep (parentheses and repeat operators)"));
  }
  bool at(char c) const { return pos_ < text_.size() && text_[pos_] == c; }
  void expect(char c) {
    if (!at(c)) fail(concat("'", c, "'"));
    ++pos_;
  }

  NodePtr alternation() {
    NodePtr first = sequence();
    if (!at('|')) return first;
    NodePtr alt = make(Node::Kind::alternation);
    alt->children.push_back(std::move(first));
    while (at('|')) {
      ++pos_;
      alt->children.push_back(sequence());
    }
    return alt;
  }

  NodePtr sequence() {
    NodePtr seq = make(Node::Kind::concat);
    while (pos_ < text_.size() && !at('|') && !at(')')) seq->children.push_back(repetition());
    if (seq->children.empty()) fail("an event, '.', '[' or '('");
    return seq;
  }

  NodePtr repetition() {
    const int depth = depth_;
    NodePtr node = atom();
    while (at('*') || at('+') || at('?') || at('{')) {
      deeper();  // each stacked operator nests the tree one level deeper
      NodePtr rep = make(Node::Kind::repeat);
      const char op = text_[pos_++];
      if (op == '*') rep->min = 0, rep->max = -1;
      else if (op == '+') rep->min = 1, rep->max = -1;
      else if (op == '?') rep->min = 0, rep->max = 1;
      else {
        rep->min = rep->max = number(0);
        const bool range = at(',');
        if (range) {
          ++pos_;
          rep->max = at('}') ? -1 : number(rep->min);
        }
        if (!at('}')) fail(range ? "'}'" : "',' or '}'");
        ++pos_;
      }
      rep->children.push_back(std::move(node));
      node = std::move(rep);
    }
    depth_ = depth;
    return node;
  }

  // A decimal count in [at_least, kMaxCount].
  int number(int at_least) {
    const std::size_t begin = pos_;
    int value = 0;
    while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9' && value <= kMaxCount)
      value = value * 10 + (text_[pos_++] - '0');
    if (pos_ == begin || value < at_least || value > kMaxCount) {
      pos_ = begin;
      fail(concat("a count from ", at_least, " to ", kMaxCount));
    }
    return value;
  }

  NodePtr atom() {
    NodePtr set = make(Node::Kind::set);
    LpeEvent event;
    if (pos_ < text_.size() && event_of(text_[pos_], event)) {
      ++pos_;
      set->events = bit(event);
    } else if (at('.')) {
      ++pos_;
      set->events = kAnyButEye;
    } else if (at('[')) {
      ++pos_;
      const bool negated = at('^');
      if (negated) ++pos_;
      EventMask listed = 0;
      while (!at(']')) {
        if (pos_ >= text_.size() || !event_of(text_[pos_], event))
          fail(listed || negated ? "an event letter or ']'" : "an event letter");
        listed |= bit(event);
        ++pos_;
      }
      if (!listed && !negated) fail("an event letter");
      ++pos_;
      set->events = negated ? EventMask(kAnyButEye & ~listed) : listed;
    } else if (at('(')) {
      ++pos_;
      deeper();
      NodePtr inner = alternation();
      expect(')');
      --depth_;
      return inner;
    } else {
      fail("an event, '.', '[' or '('");
    }
    return set;
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

// NFA states nfa.build() would make for `node`, saturating at kMaxNfaStates + 1
// (computed before building, so huge repeat counts never allocate).
std::size_t nfa_size(const Node& node) {
  static constexpr std::size_t cap = kMaxNfaStates + 1;
  auto sat = [](std::size_t a) { return std::min(a, cap); };
  switch (node.kind) {
    case Node::Kind::set: return 2;
    case Node::Kind::concat:
    case Node::Kind::alternation: {
      std::size_t n = node.kind == Node::Kind::alternation ? 2 : 0;
      for (const auto& child : node.children) n = sat(n + nfa_size(*child));
      return n;
    }
    case Node::Kind::repeat: {
      const std::size_t child = nfa_size(*node.children[0]);
      const std::size_t optional = node.max < 0 ? 1 : std::size_t(node.max - node.min);
      return sat(1 + sat(std::size_t(node.min) * child) + sat(optional * (child + 1)));
    }
  }
  return cap;
}

// Thompson construction: each fragment has one entry and one exit state.
class Nfa {
 public:
  struct State {
    std::vector<int> epsilon;
    EventMask events = 0;  // edge to `target` on any of these events
    int target = -1;
  };
  struct Fragment {
    int in, out;
  };

  Fragment build(const Node& node, bool reversed) {
    switch (node.kind) {
      case Node::Kind::set: {
        Fragment f{add(), add()};
        states[f.in].events = node.events;
        states[f.in].target = f.out;
        return f;
      }
      case Node::Kind::concat: {
        const int n = int(node.children.size());
        Fragment f = build(*node.children[reversed ? n - 1 : 0], reversed);
        for (int i = 1; i < n; ++i) {
          Fragment g = build(*node.children[reversed ? n - 1 - i : i], reversed);
          states[f.out].epsilon.push_back(g.in);
          f.out = g.out;
        }
        return f;
      }
      case Node::Kind::alternation: {
        Fragment f{add(), add()};
        for (const auto& child : node.children) {
          Fragment g = build(*child, reversed);
          states[f.in].epsilon.push_back(g.in);
          states[g.out].epsilon.push_back(f.out);
        }
        return f;
      }
      case Node::Kind::repeat: {
        // min mandatory copies, then either a loop or (max - min) optional ones.
        const int s = add();
        Fragment f{s, s};
        const Node& child = *node.children[0];
        for (int i = 0; i < node.min; ++i) f = append(f, build(child, reversed));
        const int optional = node.max < 0 ? 1 : node.max - node.min;
        for (int i = 0; i < optional; ++i) {
          Fragment g = build(child, reversed);
          const int out = add();
          states[f.out].epsilon.push_back(g.in);
          states[f.out].epsilon.push_back(out);
          states[g.out].epsilon.push_back(out);
          if (node.max < 0) states[g.out].epsilon.push_back(g.in);
          f.out = out;
        }
        return f;
      }
    }
    return {};
  }

  std::vector<State> states;

 private:
  int add() {
    states.emplace_back();
    return int(states.size()) - 1;
  }
  Fragment append(Fragment f, Fragment g) {
    states[f.out].epsilon.push_back(g.in);
    return {f.in, g.out};
  }
};

using StateSet = std::vector<char>;  // membership per NFA state

void close_over_epsilon(const Nfa& nfa, StateSet& set) {
  std::vector<int> stack;
  for (int i = 0; i < int(set.size()); ++i)
    if (set[i]) stack.push_back(i);
  while (!stack.empty()) {
    const int s = stack.back();
    stack.pop_back();
    for (int t : nfa.states[s].epsilon)
      if (!set[t]) set[t] = 1, stack.push_back(t);
  }
}

}  // namespace

LpeDfa compile_lpe(std::string_view expression, LpeOrder order) {
  const NodePtr root = Parser(expression).parse();
  if (nfa_size(*root) > kMaxNfaStates)
    throw ValueError(concat("LPE \"", expression.substr(0, 60), expression.size() > 60 ? "..." : "",
                            "\" is too large: its repeat counts multiply to more than ", kMaxNfaStates,
                            " automaton states; use smaller counts"));
  Nfa nfa;
  const Nfa::Fragment whole = nfa.build(*root, order == LpeOrder::eye_to_light);
  const std::size_t n = nfa.states.size();

  LpeDfa dfa;
  dfa.order = order;
  std::map<StateSet, int> index;
  std::vector<StateSet> pending;
  auto state_of = [&](StateSet set) {
    auto [it, inserted] = index.emplace(set, int(index.size()));
    if (inserted) {
      if (index.size() > kMaxDfaStates)
        throw ValueError(concat("LPE \"", expression.substr(0, 60), expression.size() > 60 ? "..." : "",
                                "\" is too complex: it needs more than ", kMaxDfaStates,
                                " automaton states (e.g. '.*' followed by a long counted repeat); simplify it"));
      dfa.accepting.push_back(set[whole.out]);
      dfa.next.resize(dfa.next.size() + kLpeEventCount, LpeDfa::kDead);
      pending.push_back(std::move(set));
    }
    return it->second;
  };
  StateSet initial(n, 0);
  initial[whole.in] = 1;
  close_over_epsilon(nfa, initial);
  dfa.start = state_of(std::move(initial));
  while (!pending.empty()) {
    const StateSet set = std::move(pending.back());
    pending.pop_back();
    const int from = index.at(set);
    for (int e = 0; e < kLpeEventCount; ++e) {
      StateSet moved(n, 0);
      bool any = false;
      for (std::size_t s = 0; s < n; ++s)
        if (set[s] && (nfa.states[s].events & (1u << e))) moved[nfa.states[s].target] = 1, any = true;
      if (!any) continue;
      close_over_epsilon(nfa, moved);
      dfa.next[std::size_t(from) * kLpeEventCount + e] = state_of(std::move(moved));
    }
  }
  // Live states: backward reachability from the accepting ones.
  dfa.live = dfa.accepting;
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t s = 0; s < dfa.live.size(); ++s)
      for (int e = 0; e < kLpeEventCount && !dfa.live[s]; ++e)
        if (dfa.alive(dfa.next[s * kLpeEventCount + e])) dfa.live[s] = 1, changed = true;
  }
  return dfa;
}

bool lpe_matches(const LpeDfa& dfa, std::string_view events) {
  int state = dfa.start;
  const std::size_t n = events.size();
  for (std::size_t i = 0; i < n; ++i) {
    const char c = events[dfa.order == LpeOrder::light_to_eye ? i : n - 1 - i];
    LpeEvent event;
    if (!event_of(c, event)) throw ValueError(concat("unknown path event '", c, "' in \"", events, "\""));
    state = dfa.step(state, event);
  }
  return dfa.accepts(state);
}

bool lpe_can_match(const LpeDfa& dfa) { return dfa.alive(dfa.start); }

}  // namespace tempera
