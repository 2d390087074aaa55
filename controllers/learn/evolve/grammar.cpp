// Parsing and checking BNF grammars (format: grammar.hpp).

#include "animrt/learn/evolve/grammar.hpp"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "animrt/core/input_file.hpp"

namespace animrt::evolve {
namespace {

constexpr int kInfiniteDepth = INT_MAX / 2;  // no complete derivation (yet)

struct RawProduction {
  std::string text;
  int line = 0;
  int column = 0;
};

struct RawRule {
  std::string name;
  Location where;
  std::vector<RawProduction> productions;
};

// Where a non-terminal is used, for "undefined" messages.
struct Use {
  std::size_t rule = 0;
  std::string name;
  Location where;
};

bool is_name_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == '.';
}

std::string trim(const std::string& s, std::size_t* lead = nullptr) {
  std::size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) {
    if (lead) *lead = s.size();
    return "";
  }
  std::size_t e = s.find_last_not_of(" \t\r");
  if (lead) *lead = b;
  return s.substr(b, e - b + 1);
}

bool parse_number(const std::string& s, double& out) {
  if (s.empty()) return false;
  const char* first = s.data();
  const char* last = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(first, last, out);
  return ec == std::errc() && ptr == last && std::isfinite(out);
}

int decimals(const std::string& s) {
  const auto dot = s.find('.');
  return dot == std::string::npos ? 0 : static_cast<int>(s.size() - dot - 1);
}

// `a | b | ... | c` -> a, a+(b-a), ..., c, printed with the inputs' decimals.
std::vector<RawProduction> expand_ranges(const RawRule& rule, const std::string& file) {
  std::vector<RawProduction> out;
  const auto& in = rule.productions;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i].text != "...") {
      out.push_back(in[i]);
      continue;
    }
    const Location at{file, in[i].line, in[i].column};
    double a = 0, b = 0, c = 0;
    if (i < 2 || i + 1 >= in.size() || !parse_number(in[i - 2].text, a) ||
        !parse_number(in[i - 1].text, b) || !parse_number(in[i + 1].text, c)) {
      throw InputError(at, "<" + rule.name + ">",
                       "'...' needs two numbers before it and one after (e.g. 0 | 0.5 | ... | 4)");
    }
    const double step = b - a;
    const double span = (c - b) / step;
    if (!(step != 0.0) || span < 0.0 || std::fabs(span - std::round(span)) > 1e-6 ||
        span > 100000.0) {
      throw InputError(at, "<" + rule.name + ">",
                       "range " + in[i - 2].text + " | " + in[i - 1].text + " | ... | " +
                           in[i + 1].text + " does not reach its end in whole steps");
    }
    const int digits =
        std::max({decimals(in[i - 2].text), decimals(in[i - 1].text), decimals(in[i + 1].text)});
    const long n = std::lround(span);
    for (long k = 1; k < n; ++k) {  // b and c are the neighbours
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.*f", digits, b + static_cast<double>(k) * step);
      std::string v = buf;
      if (v == "-0" || v.find_first_not_of("-0.") == std::string::npos) v = "0";
      out.push_back({v, in[i].line, in[i].column});
    }
  }
  return out;
}

// Splits a production's text into terminals and non-terminals.
std::vector<Symbol> split_symbols(const RawProduction& p, const RawRule& rule,
                                  const std::string& file, std::vector<Use>& uses,
                                  std::size_t rule_index) {
  std::vector<Symbol> symbols;
  std::string text;
  const std::string& s = p.text;
  for (std::size_t i = 0; i < s.size();) {
    if (s[i] != '<') {
      text += s[i++];
      continue;
    }
    std::size_t j = i + 1;
    while (j < s.size() && is_name_char(s[j])) ++j;
    const Location at{file, p.line, p.column + static_cast<int>(i)};
    if (j >= s.size() || s[j] != '>' || j == i + 1) {
      throw InputError(at, "<" + rule.name + ">", "expected a non-terminal name and '>' after '<'");
    }
    if (!text.empty()) symbols.push_back({true, text, -1});
    text.clear();
    std::string name = s.substr(i + 1, j - i - 1);
    uses.push_back({rule_index, name, at});
    symbols.push_back({false, std::move(name), -1});
    i = j + 1;
  }
  if (!text.empty()) symbols.push_back({true, text, -1});
  return symbols;
}

}  // namespace

Grammar Grammar::load_file(const std::string& path) { return parse(read_input_file(path), path); }

int Grammar::find(const std::string& name) const {
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    if (rules_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

Grammar Grammar::parse(const std::string& text, const std::string& file_name) {
  std::vector<RawRule> raw;
  std::unordered_map<std::string, std::size_t> index;  // rule name -> position in raw
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    // Comments run from '#' to the end of the line.
    if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::size_t lead = 0;
    const std::string body = trim(line, &lead);
    if (body.empty()) continue;
    std::size_t rest_at = 0;  // offset in `line` where productions start
    if (body[0] == '<') {
      const auto def = line.find("::=", lead);
      const auto close = line.find('>', lead);
      if (def == std::string::npos || close == std::string::npos || close > def) {
        throw InputError({file_name, line_no, static_cast<int>(lead) + 1}, "",
                         "expected '<name> ::= ...'");
      }
      const std::string name = line.substr(lead + 1, close - lead - 1);
      const bool name_ok = !name.empty() && std::all_of(name.begin(), name.end(), is_name_char);
      if (!name_ok || !trim(line.substr(close + 1, def - close - 1)).empty()) {
        throw InputError({file_name, line_no, static_cast<int>(lead) + 1}, "",
                         "expected '<name> ::= ...'");
      }
      if (const auto it = index.find(name); it != index.end()) {
        throw InputError({file_name, line_no, static_cast<int>(lead) + 1}, "<" + name + ">",
                         "rule defined twice (first at line " +
                             std::to_string(raw[it->second].where.line) + ")");
      }
      index.emplace(name, raw.size());
      raw.push_back({name, {file_name, line_no, static_cast<int>(lead) + 1}, {}});
      rest_at = def + 3;
    } else if (body[0] == '|') {
      if (raw.empty()) {
        throw InputError({file_name, line_no, static_cast<int>(lead) + 1}, "",
                         "'|' before any rule");
      }
      rest_at = lead + 1;
    } else {
      throw InputError({file_name, line_no, static_cast<int>(lead) + 1}, "",
                       "expected '<name> ::= ...' or a line starting with '|'");
    }
    // Productions separated by '|' (outside <...>).
    RawRule& rule = raw.back();
    std::size_t start = rest_at;
    for (std::size_t i = rest_at; i <= line.size(); ++i) {
      if (i < line.size() && line[i] != '|') continue;
      const std::string piece = line.substr(start, i - start);
      std::size_t plead = 0;
      const std::string p = trim(piece, &plead);
      const int column = static_cast<int>(start + plead) + 1;
      if (p.empty()) {
        // "<a> ::=" alone on a line continues with '|' lines; anything else is empty.
        const bool bare_head = (i == line.size() && start == rest_at && body[0] == '<');
        if (!bare_head) {
          throw InputError({file_name, line_no, column}, "<" + rule.name + ">", "empty production");
        }
      } else {
        rule.productions.push_back({p, line_no, column});
      }
      start = i + 1;
    }
  }
  if (raw.empty()) throw InputError({file_name, 0, 0}, "", "the grammar has no rules");

  Grammar g;
  g.file_ = file_name;
  std::vector<Use> uses;
  for (std::size_t r = 0; r < raw.size(); ++r) {
    if (raw[r].productions.empty()) {
      throw InputError(raw[r].where, "<" + raw[r].name + ">", "rule has no productions");
    }
    Rule rule;
    rule.name = raw[r].name;
    rule.where = raw[r].where;
    for (const auto& p : expand_ranges(raw[r], file_name)) {
      rule.productions.push_back({split_symbols(p, raw[r], file_name, uses, r), false, 0});
    }
    g.rules_.push_back(std::move(rule));
  }
  // Resolve non-terminals.
  std::size_t use = 0;
  for (auto& rule : g.rules_) {
    for (auto& prod : rule.productions) {
      for (auto& sym : prod.symbols) {
        if (sym.terminal) continue;
        const auto it = index.find(sym.text);
        sym.rule = it == index.end() ? -1 : static_cast<int>(it->second);
        if (sym.rule < 0) {
          throw InputError(uses[use].where, "<" + rule.name + ">",
                           "undefined non-terminal <" + sym.text + ">");
        }
        ++use;
      }
    }
  }
  g.link_and_check();
  return g;
}

void Grammar::link_and_check() {
  const std::size_t n = rules_.size();
  // Reachability from the start rule.
  std::vector<char> reached(n, 0);
  std::vector<int> todo{0};
  reached[0] = 1;
  while (!todo.empty()) {
    const int r = todo.back();
    todo.pop_back();
    for (const auto& p : rules_[static_cast<std::size_t>(r)].productions) {
      for (const auto& s : p.symbols) {
        if (!s.terminal && !reached[static_cast<std::size_t>(s.rule)]) {
          reached[static_cast<std::size_t>(s.rule)] = 1;
          todo.push_back(s.rule);
        }
      }
    }
  }
  for (std::size_t r = 0; r < n; ++r) {
    if (!reached[r]) {
      throw InputError(rules_[r].where, "<" + rules_[r].name + ">",
                       "unreachable from the start rule <" + rules_[0].name + ">");
    }
  }
  // Every step below is linear in the grammar's size, so a huge grammar is
  // checked (and rejected) quickly.
  compute_min_depths();
  for (const auto& r : rules_) {
    if (r.min_depth >= kInfiniteDepth) {
      throw InputError(r.where, "<" + r.name + ">",
                       "recursion with no terminal exit: every production leads back to it");
    }
  }
  mark_recursion();
}

// Shallowest complete derivation of each rule: a production's depth is one
// more than the deepest rule it uses, a rule's the least of its productions'.
// Rules are settled in order of depth (a breadth-first form of Knuth's
// generalisation of Dijkstra's algorithm): a production is complete once
// every rule it uses is settled. A rule never settled recurses without exit.
void Grammar::compute_min_depths() {
  const std::size_t n = rules_.size();
  struct Occurrence {
    std::size_t rule, production;
  };
  std::vector<std::vector<Occurrence>> used_by(n);
  std::vector<std::vector<int>> pending(n);  // unsettled non-terminals per production
  std::vector<int> queue;                    // rules in order of (non-decreasing) depth
  std::vector<char> settled(n, 0);
  for (std::size_t a = 0; a < n; ++a) {
    Rule& rule = rules_[a];
    rule.min_depth = kInfiniteDepth;
    pending[a].assign(rule.productions.size(), 0);
    for (std::size_t p = 0; p < rule.productions.size(); ++p) {
      rule.productions[p].min_depth = kInfiniteDepth;
      for (const auto& sym : rule.productions[p].symbols) {
        if (sym.terminal) continue;
        used_by[static_cast<std::size_t>(sym.rule)].push_back({a, p});
        ++pending[a][p];
      }
      if (pending[a][p] == 0) {
        rule.productions[p].min_depth = 1;
        if (rule.min_depth > 1) {
          rule.min_depth = 1;
          queue.push_back(static_cast<int>(a));
        }
      }
    }
  }
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const auto b = static_cast<std::size_t>(queue[head]);
    if (settled[b]) continue;
    settled[b] = 1;
    const int depth = rules_[b].min_depth + 1;
    for (const Occurrence& o : used_by[b]) {
      if (--pending[o.rule][o.production] != 0) continue;
      // b is the deepest rule this production uses: rules settle in order.
      Rule& user = rules_[o.rule];
      user.productions[o.production].min_depth = depth;
      if (depth < user.min_depth) {
        user.min_depth = depth;
        queue.push_back(static_cast<int>(o.rule));
      }
    }
  }
}

// A production is recursive when it uses a rule that can derive the rule it
// belongs to: the two are in one strongly connected component of the
// rule graph (Tarjan's algorithm, iterative).
void Grammar::mark_recursion() {
  const std::size_t n = rules_.size();
  constexpr int kUnvisited = -1;
  std::vector<int> order(n, kUnvisited), low(n, 0), component(n, -1);
  std::vector<char> on_stack(n, 0);
  std::vector<int> stack;
  struct Frame {
    std::size_t rule, production, symbol;
  };
  std::vector<Frame> frames;
  int counter = 0, components = 0;
  for (std::size_t root = 0; root < n; ++root) {
    if (order[root] != kUnvisited) continue;
    frames.push_back({root, 0, 0});
    order[root] = low[root] = counter++;
    stack.push_back(static_cast<int>(root));
    on_stack[root] = 1;
    while (!frames.empty()) {
      Frame& f = frames.back();
      const auto& prods = rules_[f.rule].productions;
      if (f.production < prods.size()) {
        const auto& syms = prods[f.production].symbols;
        if (f.symbol >= syms.size()) {
          ++f.production;
          f.symbol = 0;
          continue;
        }
        const auto& sym = syms[f.symbol++];
        if (sym.terminal) continue;
        const auto next = static_cast<std::size_t>(sym.rule);
        if (order[next] == kUnvisited) {
          order[next] = low[next] = counter++;
          stack.push_back(static_cast<int>(next));
          on_stack[next] = 1;
          frames.push_back({next, 0, 0});
        } else if (on_stack[next]) {
          low[f.rule] = std::min(low[f.rule], order[next]);
        }
        continue;
      }
      const std::size_t done = f.rule;
      frames.pop_back();
      if (!frames.empty()) low[frames.back().rule] = std::min(low[frames.back().rule], low[done]);
      if (low[done] == order[done]) {
        while (true) {
          const auto member = static_cast<std::size_t>(stack.back());
          stack.pop_back();
          on_stack[member] = 0;
          component[member] = components;
          if (member == done) break;
        }
        ++components;
      }
    }
  }
  for (std::size_t a = 0; a < n; ++a) {
    for (auto& p : rules_[a].productions) {
      for (const auto& sym : p.symbols) {
        if (!sym.terminal && component[static_cast<std::size_t>(sym.rule)] == component[a])
          p.recursive = true;
      }
      if (p.recursive) rules_[a].recursive = true;
    }
  }
}

}  // namespace animrt::evolve
