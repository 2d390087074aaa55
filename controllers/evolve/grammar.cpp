// Parsing and checking BNF grammars (format: grammar.hpp).

#include "animrt/controllers/evolve/grammar.hpp"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace animrt::evolve {
namespace {

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

Grammar Grammar::load_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError({path, 0, 0}, "", "cannot open grammar file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse(ss.str(), path);
}

int Grammar::find(const std::string& name) const {
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    if (rules_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

Grammar Grammar::parse(const std::string& text, const std::string& file_name) {
  std::vector<RawRule> raw;
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
      for (const auto& r : raw) {
        if (r.name == name) {
          throw InputError(
              {file_name, line_no, static_cast<int>(lead) + 1}, "<" + name + ">",
              "rule defined twice (first at line " + std::to_string(r.where.line) + ")");
        }
      }
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
        sym.rule = g.find(sym.text);
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
  // Shallowest complete derivation of each rule (fixpoint); a rule left at
  // infinity recurses with no way to finish.
  constexpr int kInf = INT_MAX / 2;
  for (auto& r : rules_) r.min_depth = kInf;
  for (bool changed = true; changed;) {
    changed = false;
    for (auto& r : rules_) {
      for (auto& p : r.productions) {
        int d = 1;
        for (const auto& s : p.symbols) {
          if (!s.terminal) d = std::max(d, rules_[static_cast<std::size_t>(s.rule)].min_depth + 1);
        }
        p.min_depth = std::min(d, kInf);
        if (p.min_depth < r.min_depth) {
          r.min_depth = p.min_depth;
          changed = true;
        }
      }
    }
  }
  for (const auto& r : rules_) {
    if (r.min_depth >= kInf) {
      throw InputError(r.where, "<" + r.name + ">",
                       "recursion with no terminal exit: every production leads back to it");
    }
  }
  // reach[a][b]: rule a can derive rule b.
  std::vector<std::vector<char>> reach(n, std::vector<char>(n, 0));
  for (std::size_t a = 0; a < n; ++a) {
    std::vector<int> stack;
    for (const auto& p : rules_[a].productions) {
      for (const auto& s : p.symbols) {
        if (!s.terminal) stack.push_back(s.rule);
      }
    }
    while (!stack.empty()) {
      const auto b = static_cast<std::size_t>(stack.back());
      stack.pop_back();
      if (reach[a][b]) continue;
      reach[a][b] = 1;
      for (const auto& p : rules_[b].productions) {
        for (const auto& s : p.symbols) {
          if (!s.terminal && !reach[a][static_cast<std::size_t>(s.rule)]) stack.push_back(s.rule);
        }
      }
    }
  }
  for (std::size_t a = 0; a < n; ++a) {
    for (auto& p : rules_[a].productions) {
      for (const auto& s : p.symbols) {
        const auto b = static_cast<std::size_t>(s.rule);
        if (!s.terminal && (b == a || reach[b][a])) p.recursive = true;
      }
      if (p.recursive) rules_[a].recursive = true;
    }
  }
}

}  // namespace animrt::evolve
