// Phenotype text -> gait file (see phenotype.hpp).

#include "animrt/learn/evolve/phenotype.hpp"

#include <charconv>

#include "animrt/controllers/gait/expression.hpp"

namespace animrt::evolve {
namespace {

std::string strip_blanks(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

}  // namespace

PhenotypeGait make_phenotype_gait(const GaitFile& seed, const std::string& phenotype,
                                  const std::vector<std::string>& held) {
  PhenotypeGait out;
  std::vector<std::string> pieces;
  std::size_t start = 0;
  for (;;) {
    const auto semi = phenotype.find(';', start);
    pieces.push_back(strip_blanks(phenotype.substr(start, semi - start)));
    if (semi == std::string::npos) break;
    start = semi + 1;
  }
  if (pieces.size() != seed.curves.size()) {
    out.error = "phenotype has " + std::to_string(pieces.size()) + " curves, the seed gait " +
                std::to_string(seed.curves.size());
    return out;
  }
  out.gait = seed;
  out.gait.file.clear();
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    auto& curve = out.gait.curves[i];
    curve.where = Location{};
    if (i < held.size() && !held[i].empty()) {
      curve.expression = held[i];
    } else {
      // Store the compiled form: evaluation is identical and the text is tidy.
      try {
        curve.expression = Expression::compile(pieces[i]).to_string();
      } catch (const ExpressionError& e) {
        out.error = "curve " + curve.name + ": " + e.what();
        return out;
      }
    }
  }
  try {
    validate_gait(out.gait);
  } catch (const InputError& e) {
    out.error = e.what();
    return out;
  }
  out.valid = true;
  return out;
}

std::vector<std::string> curve_means(const GaitFile& seed) {
  std::vector<std::string> out;
  constexpr int kSamples = 256;
  for (const auto& c : seed.curves) {
    const Expression e = Expression::compile(c.expression);
    double sum = 0;
    for (int i = 0; i < kSamples; ++i) sum += e.eval(static_cast<double>(i) / kSamples);
    char buf[32];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, sum / kSamples);
    (void)ec;
    out.emplace_back(buf, end);
  }
  return out;
}

}  // namespace animrt::evolve
