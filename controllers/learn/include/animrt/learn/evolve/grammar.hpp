#pragma once
// BNF grammars for Grammatical Evolution (configs/grammars/*.bnf).
//
//   # comment to the end of the line
//   <rule> ::= production | production ...
//          |  production                     (a line starting with '|' continues)
//
// A production is literal text with <non-terminals> in it; the text between
// non-terminals is kept verbatim (spaces included), so a phenotype is the
// concatenation of the terminal text of its derivation. Numeric ranges can
// be written compactly: `0 | 0.25 | ... | 20` expands to every step of 0.25
// from 0 to 20. The first rule is the start symbol.
//
// Loading rejects, with file:line:column: <rule>: message, syntax errors,
// duplicate rules, undefined non-terminals, rules the start cannot reach,
// and rules that can never finish (recursion without a terminal exit).

#include <string>
#include <vector>

#include "animrt/core/error.hpp"

namespace animrt::evolve {

struct Symbol {
  bool terminal = true;
  std::string text;  // terminal text, or the non-terminal's name (without <>)
  int rule = -1;     // index into Grammar::rules() for non-terminals
};

struct Production {
  std::vector<Symbol> symbols;
  bool recursive = false;  // can derive its own rule again
  int min_depth = 0;       // depth of the shallowest complete derivation from here
};

struct Rule {
  std::string name;
  std::vector<Production> productions;
  Location where;
  bool recursive = false;
  int min_depth = 0;
};

class Grammar {
 public:
  static Grammar load_file(const std::string& path);
  static Grammar parse(const std::string& text, const std::string& file_name);

  const std::vector<Rule>& rules() const { return rules_; }
  const Rule& start() const { return rules_.front(); }
  int find(const std::string& name) const;  // -1 when absent
  const std::string& file() const { return file_; }

 private:
  void link_and_check();
  void compute_min_depths();
  void mark_recursion();
  std::vector<Rule> rules_;
  std::string file_;
};

}  // namespace animrt::evolve
