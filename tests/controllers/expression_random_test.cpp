// Random expressions: the compiled program must equal a plain recursive
// evaluation of the tree bit for bit, and survive to_string() unchanged.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "animrt/controllers/gait/expression.hpp"
#include "animrt/core/joint.hpp"

namespace animrt {
namespace {

struct Node {
  enum Kind { kNum, kT, kPi, kNeg, kSin, kCos, kAdd, kSub, kMul, kDiv } kind = kNum;
  double value = 0.0;
  std::string literal;
  std::unique_ptr<Node> a, b;
};

// The reference: each node evaluated from its children, nothing folded.
double reference(const Node& n, double t) {
  switch (n.kind) {
    case Node::kNum:
      return n.value;
    case Node::kT:
      return t;
    case Node::kPi:
      return kPi;
    case Node::kNeg:
      return -reference(*n.a, t);
    case Node::kSin:
      return std::sin(reference(*n.a, t));
    case Node::kCos:
      return std::cos(reference(*n.a, t));
    default:
      break;
  }
  const double l = reference(*n.a, t);
  const double r = reference(*n.b, t);
  switch (n.kind) {
    case Node::kAdd:
      return l + r;
    case Node::kSub:
      return l - r;
    case Node::kMul:
      return l * r;
    default:
      return r == 0.0 ? 1.0 : l / r;
  }
}

class Generator {
 public:
  explicit Generator(std::uint32_t seed) : rng_(seed) {}

  std::unique_ptr<Node> tree(int depth) {
    auto n = std::make_unique<Node>();
    if (depth == 0 || chance(0.25)) {
      leaf(*n);
      return n;
    }
    const int pick = uniform(0, 9);
    if (pick < 2) {
      n->kind = pick == 0 ? Node::kNeg : (chance(0.5) ? Node::kSin : Node::kCos);
      n->a = tree(depth - 1);
      return n;
    }
    static const Node::Kind kBinary[] = {Node::kAdd, Node::kSub, Node::kMul, Node::kDiv};
    n->kind = kBinary[uniform(0, 3)];
    n->a = tree(depth - 1);
    n->b = tree(depth - 1);
    return n;
  }

  struct Text {
    std::string s;
    int prec;  // 1 sum, 2 product, 3 unary, 4 atom
  };

  // Minimal parentheses, plus some extra ones and random spacing.
  Text print(const Node& n) {
    switch (n.kind) {
      case Node::kNum:
        return {n.literal, 4};
      case Node::kT:
        return {"t", 4};
      case Node::kPi:
        return {"PI", 4};
      case Node::kNeg: {
        Text x = print(*n.a);
        return {"-" + space() + wrap(x, x.prec < 3), 3};
      }
      case Node::kSin:
      case Node::kCos:
        return {std::string(n.kind == Node::kSin ? "sin" : "cos") + space() + "(" + space() +
                    print(*n.a).s + space() + ")",
                4};
      default:
        break;
    }
    const int prec = (n.kind == Node::kAdd || n.kind == Node::kSub) ? 1 : 2;
    static const char kSymbols[] = "+-*/";
    const char op = kSymbols[n.kind - Node::kAdd];
    Text l = print(*n.a);
    Text r = print(*n.b);
    return {wrap(l, l.prec < prec) + space() + op + space() + wrap(r, r.prec <= prec), prec};
  }

 private:
  void leaf(Node& n) {
    const int pick = uniform(0, 9);
    if (pick < 4) {
      n.kind = Node::kT;
      return;
    }
    if (pick == 4) {
      n.kind = Node::kPi;
      return;
    }
    n.kind = Node::kNum;
    static const char* const kLiterals[] = {"0",    "1",      "2",    "3",     "6.97",   "1.07",
                                            "2.56", "7.7",    "2.97", "0.25",  "1e-3",   ".5",
                                            "3.",   "2.5E+2", "0.1",  "1e300", "1e-300", "10"};
    char buf[40];
    switch (uniform(0, 2)) {
      case 0:
        n.literal = kLiterals[uniform(0, static_cast<int>(std::size(kLiterals)) - 1)];
        break;
      case 1:
        std::snprintf(buf, sizeof buf, "%.17g",
                      std::uniform_real_distribution<double>(0, 10)(rng_));
        n.literal = buf;
        break;
      default:
        std::snprintf(buf, sizeof buf, "%.17g",
                      std::exp(std::uniform_real_distribution<double>(-20, 20)(rng_)));
        n.literal = buf;
        break;
    }
    n.value = std::strtod(n.literal.c_str(), nullptr);
  }

  std::string wrap(const Text& x, bool needed) {
    return needed || chance(0.1) ? "(" + space() + x.s + space() + ")" : x.s;
  }
  std::string space() { return chance(0.3) ? " " : ""; }
  bool chance(double p) { return std::uniform_real_distribution<double>(0, 1)(rng_) < p; }
  int uniform(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }

  std::mt19937 rng_;
};

const double kTimes[] = {0.0, 0.25, 0.5, 1.0, -0.3, 3.7, 1e-9, 123.456, -1e6, 0.123456789};

TEST(ExpressionRandom, EqualsTreeEvaluationBitForBit) {
  Generator gen(12345);
  int compared = 0;
  for (int i = 0; i < 3000; ++i) {
    const auto tree = gen.tree(1 + i % 7);
    const std::string text = gen.print(*tree).s;
    const Expression e = Expression::compile(text);
    for (double t : kTimes) {
      const double want = reference(*tree, t);
      const double got = e.eval(t);
      ASSERT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(want))
          << text << "\n  at t = " << t << ": " << got << " vs " << want;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 3000 * static_cast<int>(std::size(kTimes)));
}

TEST(ExpressionRandom, ToStringRoundTrips) {
  Generator gen(777);
  for (int i = 0; i < 3000; ++i) {
    const auto tree = gen.tree(1 + i % 7);
    const std::string text = gen.print(*tree).s;
    const Expression e = Expression::compile(text);
    const std::string printed = e.to_string();
    const Expression back = Expression::compile(printed);
    ASSERT_EQ(back.to_string(), printed) << text;
    ASSERT_EQ(back.size(), e.size()) << text;
    for (double t : kTimes) {
      ASSERT_EQ(std::bit_cast<std::uint64_t>(back.eval(t)), std::bit_cast<std::uint64_t>(e.eval(t)))
          << text << "\n  printed " << printed;
    }
  }
}

}  // namespace
}  // namespace animrt
