// Reading the evolve run file (see run_config.hpp).

#include "animrt/learn/evolve/run_config.hpp"

#include <cstdint>
#include <filesystem>
#include <utility>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt::evolve {
namespace {

std::string resolve(const std::string& base_file, const std::string& path) {
  if (path.empty() || path[0] == '/' || base_file.empty()) return path;
  return (std::filesystem::path(base_file).parent_path() / path).lexically_normal().string();
}

int get_int(const YamlNode& n, std::string_view key, int fallback, int lo, int hi) {
  const auto v = n.find(key);
  return v ? static_cast<int>(v->as_int_in(lo, hi)) : fallback;
}

double get_in(const YamlNode& n, std::string_view key, double fallback, double lo, double hi) {
  const auto v = n.find(key);
  return v ? v->as_double_in(lo, hi) : fallback;
}

RunConfig from_root(const YamlNode& root) {
  root.allow_only(
      {"name", "grammar", "model", "seed_gait", "robot", "search", "walk", "fitness", "threads"});
  RunConfig c;
  c.file = root.file();
  c.name = root.at("name").as_string();
  if (c.name.empty()) root.at("name").fail("expected a non-empty name");
  c.grammar = resolve(c.file, root.at("grammar").as_string());
  c.model = resolve(c.file, root.at("model").as_string());
  c.seed_gait = resolve(c.file, root.at("seed_gait").as_string());
  c.threads = get_int(root, "threads", 0, 0, 1024);
  if (auto r = root.find("robot")) c.robot = resolve(c.file, r->as_string());

  if (auto s = root.find("search")) {
    s->allow_only({"seed", "population", "generations", "elites", "tournament", "crossover",
                   "mutation", "max_wraps", "mapping", "remember_walks", "max_depth",
                   "grow_probability", "tail_ratio", "codon_size"});
    SearchSettings& ss = c.search;
    if (auto v = s->find("seed")) ss.seed = static_cast<std::uint64_t>(v->as_int_in(0, INT64_MAX));
    ss.population = get_int(*s, "population", ss.population, 2, 1000000);
    ss.generations = get_int(*s, "generations", ss.generations, 0, 1000000);
    ss.elites = get_int(*s, "elites", ss.elites, 0, 1000000);
    ss.tournament = get_int(*s, "tournament", ss.tournament, 1, 1000);
    ss.crossover = get_in(*s, "crossover", ss.crossover, 0, 1);
    ss.mutation = get_in(*s, "mutation", ss.mutation, 0, 1);
    ss.max_wraps = get_int(*s, "max_wraps", ss.max_wraps, 0, 100);
    if (auto v = s->find("mapping")) {
      const std::string m = v->as_string();
      if (m == "structured") {
        ss.mapping = Mapping::structured;
      } else if (m != "standard") {
        v->fail("expected standard or structured, got '" + elide(m) + "'");
      }
      ss.mapping_where = v->location();
    }
    if (auto v = s->find("remember_walks")) ss.remember_walks = v->as_bool();
    ss.init.max_depth = get_int(*s, "max_depth", ss.init.max_depth, 1, 100);
    ss.init.grow_probability = get_in(*s, "grow_probability", ss.init.grow_probability, 0, 1);
    ss.init.tail_ratio = get_in(*s, "tail_ratio", ss.init.tail_ratio, 0, 10);
    ss.init.codon_size = static_cast<std::uint32_t>(get_int(*s, "codon_size", 1 << 16, 2, 1 << 30));
    if (ss.elites >= ss.population) {
      s->at("elites").fail("expected fewer elites than the population (" +
                           std::to_string(ss.population) + ")");
    }
  }
  if (auto w = root.find("walk")) {
    w->allow_only({"settle_s", "warmup_cycles", "measure_cycles"});
    c.walk.settle_s = get_in(*w, "settle_s", c.walk.settle_s, 0, 60);
    c.walk.warmup_cycles = get_int(*w, "warmup_cycles", c.walk.warmup_cycles, 0, 100);
    c.walk.measure_cycles = get_int(*w, "measure_cycles", c.walk.measure_cycles, 1, 100);
  }
  if (auto f = root.find("fitness")) {
    f->allow_only({"weights", "freedom"});
    if (auto ws = f->find("weights")) {
      int previous = -1;
      for (const auto& item : ws->items()) {
        item.allow_only({"from_generation", "distance", "duty_factor", "stride_length", "energy"});
        WeightStage st;
        st.from_generation = static_cast<int>(item.at("from_generation").as_int_in(0, 1000000));
        if (st.from_generation <= previous || (previous < 0 && st.from_generation != 0)) {
          item.at("from_generation")
              .fail(previous < 0 ? "the first stage must start at generation 0"
                                 : "stages must start at increasing generations");
        }
        previous = st.from_generation;
        st.weights.distance = get_in(item, "distance", 1, 0, 1e6);
        st.weights.duty_factor = get_in(item, "duty_factor", 1, 0, 1e6);
        st.weights.stride_length = get_in(item, "stride_length", 1, 0, 1e6);
        st.weights.energy = get_in(item, "energy", 1, 0, 1e6);
        if (st.weights.distance == 0 && st.weights.duty_factor == 0 &&
            st.weights.stride_length == 0 && st.weights.energy == 0) {
          item.fail("every weight is 0: the stage would rank every gait the same");
        }
        c.weights.push_back(st);
      }
      if (c.weights.empty())
        ws->fail("expected at least one stage (leave weights out for the defaults)");
    }
    if (auto fr = f->find("freedom")) {
      int previous = -1;
      for (const auto& item : fr->items()) {
        item.allow_only({"from_generation", "free"});
        FreedomStage st;
        st.where = item.at("free").location();
        st.from_generation = static_cast<int>(item.at("from_generation").as_int_in(0, 1000000));
        if (st.from_generation <= previous || (previous < 0 && st.from_generation != 0)) {
          item.at("from_generation")
              .fail(previous < 0 ? "the first stage must start at generation 0"
                                 : "stages must start at increasing generations");
        }
        previous = st.from_generation;
        for (const auto& name : item.at("free").items()) st.free.push_back(name.as_string());
        c.freedom.push_back(st);
      }
    }
  }
  if (c.weights.empty()) c.weights.push_back({});
  return c;
}

}  // namespace

RunConfig load_run_config(const std::string& path) {
  const YamlNode root = YamlNode::load_file(path);
  RunConfig c = from_root(root);
  // The files it names are checked here, so that a missing one is reported
  // at its key in the run file rather than later by the loader alone.
  const std::pair<const char*, const std::string*> files[] = {
      {"grammar", &c.grammar}, {"model", &c.model}, {"seed_gait", &c.seed_gait}};
  for (const auto& [key, file] : files) {
    if (const std::string problem = input_file_problem(*file, kMaxMediaFileBytes);
        !problem.empty()) {
      root.at(key).fail(quote_path(*file) + " " + problem);
    }
  }
  return c;
}

RunConfig parse_run_config(const std::string& text, const std::string& file_name) {
  return from_root(YamlNode::load_string(text, file_name));
}

}  // namespace animrt::evolve
