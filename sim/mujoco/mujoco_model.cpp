// Loading and checking MJCF models (see mujoco_model.hpp).

#include "animrt/sim/mujoco/mujoco_model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"

namespace animrt::sim {

int MujocoModel::actuator_of(const std::string& joint) const {
  for (std::size_t i = 0; i < actuated_joints.size(); ++i) {
    if (actuated_joints[i] == joint) return static_cast<int>(i);
  }
  return -1;
}

namespace {

// The line (from 1) of the first attribute `name` (a blank before it, "="
// after it and blanks between) outside XML comments, or 0.
int attribute_line(const std::string& text, std::string_view name) {
  std::size_t at = 0;
  while ((at = text.find(name, at)) != std::string::npos) {
    const std::size_t comment = text.rfind("<!--", at);
    const std::size_t comment_end = comment == std::string::npos ? 0 : text.find("-->", comment);
    const bool in_comment =
        comment != std::string::npos && (comment_end == std::string::npos || comment_end > at);
    std::size_t after = at + name.size();
    while (after < text.size() && std::isspace(static_cast<unsigned char>(text[after]))) ++after;
    const bool attribute = at > 0 && std::isspace(static_cast<unsigned char>(text[at - 1])) &&
                           after < text.size() && text[after] == '=';
    if (attribute && !in_comment) {
      return 1 + static_cast<int>(std::count(text.begin(),
                                             text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
    }
    at += name.size();
  }
  return 0;
}

// An attribute value token that reads whole as a number that is not finite
// ("nan", "inf", "-Infinity"): MuJoCo loads some of them with a warning of
// its own, and the physics then computes NaN.
bool non_finite_token(std::string_view token) {
  const std::string t(token);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  return end == t.c_str() + t.size() && !t.empty() && !std::isfinite(v);
}

// The first attribute outside comments whose value holds a non-finite
// number: its line and column (from 1), "element.attribute" and the token.
struct NonFinite {
  int line = 0, column = 0;
  std::string attribute, token;
};

std::optional<NonFinite> first_non_finite(const std::string& text) {
  int line = 1;
  std::size_t line_start = 0;
  bool in_tag = false;
  std::string element;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
      continue;
    }
    if (!in_tag && text.compare(i, 4, "<!--") == 0) {
      const std::size_t end = text.find("-->", i + 4);
      const std::size_t stop = end == std::string::npos ? text.size() : end + 3;
      for (std::size_t k = i; k < stop; ++k) {
        if (text[k] == '\n') {
          ++line;
          line_start = k + 1;
        }
      }
      i = stop - 1;
      continue;
    }
    if (text[i] == '<') {
      in_tag = true;
      std::size_t e = i + 1;
      while (e < text.size() && !std::isspace(static_cast<unsigned char>(text[e])) &&
             text[e] != '>' && text[e] != '/') {
        ++e;
      }
      element = text.substr(i + 1, e - i - 1);
    }
    if (text[i] == '>') in_tag = false;
    if (!in_tag || text[i] != '=') continue;
    std::size_t q = i + 1;
    while (q < text.size() && std::isspace(static_cast<unsigned char>(text[q]))) ++q;
    if (q >= text.size() || (text[q] != '"' && text[q] != '\'')) continue;
    const std::size_t close = text.find(text[q], q + 1);
    if (close == std::string::npos) return std::nullopt;  // MuJoCo's parser says where
    std::size_t name_end = i;
    while (name_end > 0 && std::isspace(static_cast<unsigned char>(text[name_end - 1]))) --name_end;
    std::size_t name_start = name_end;
    while (name_start > 0 && !std::isspace(static_cast<unsigned char>(text[name_start - 1])) &&
           text[name_start - 1] != '<') {
      --name_start;
    }
    const std::string_view value(text.data() + q + 1, close - q - 1);
    std::size_t t = 0;
    while (t < value.size()) {
      while (t < value.size() && std::isspace(static_cast<unsigned char>(value[t]))) ++t;
      std::size_t e = t;
      while (e < value.size() && !std::isspace(static_cast<unsigned char>(value[e]))) ++e;
      if (e > t && non_finite_token(value.substr(t, e - t))) {
        NonFinite f;
        f.line = line;
        f.column = static_cast<int>(q + 2 + t - line_start);
        f.attribute = element + "." + text.substr(name_start, name_end - name_start);
        f.token = std::string(value.substr(t, e - t));
        return f;
      }
      t = e;
    }
    // A value that spans lines moves the line count on.
    for (std::size_t k = q; k < close; ++k) {
      if (text[k] == '\n') {
        ++line;
        line_start = k + 1;
      }
    }
    i = close;
  }
  return std::nullopt;
}

// MuJoCo writes its own warnings (to the terminal and a MUJOCO_LOG.TXT in
// the working folder); while a model loads they are kept and told as ours.
thread_local std::vector<std::string>* load_warnings = nullptr;

void keep_warning(const char* message) {
  if (load_warnings != nullptr) load_warnings->emplace_back(message);
}

class KeptWarnings {
 public:
  KeptWarnings() : previous_(mju_user_warning) {
    load_warnings = &list;
    mju_user_warning = keep_warning;
  }
  ~KeptWarnings() {
    mju_user_warning = previous_;
    load_warnings = nullptr;
  }
  KeptWarnings(const KeptWarnings&) = delete;
  KeptWarnings& operator=(const KeptWarnings&) = delete;
  std::vector<std::string> list;

 private:
  void (*previous_)(const char*);
};

}  // namespace

void check_mujoco_timestep(const mjModel& model, const std::string& path) {
  // From 10 us (a run steps physics up to each cycle's time: a step much
  // finer than that takes the run's time by itself) to 0.1 s.
  constexpr double kMinStepS = 1e-5, kMaxStepS = 0.1;
  const double step = model.opt.timestep;
  if (step >= kMinStepS && step <= kMaxStepS) return;
  // The line of the attribute (timestep="..."), where the file has one,
  // outside comments.
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const int line = attribute_line(text, "timestep");
  char found[32];
  std::snprintf(found, sizeof found, "%g", step);
  throw InputError({path, line, 0}, "option.timestep",
                   std::string("expected a time step from 1e-05 to 0.1 s, found ") + found);
}

mjModel* read_mjcf(const std::string& path, std::string& error) {
  if (const auto bad = first_non_finite(read_input_file(path, kMaxMediaFileBytes))) {
    throw InputError({path, bad->line, bad->column}, bad->attribute,
                     "expected finite numbers, found " + bad->token);
  }
  char text[1024] = "";
  mjModel* model = nullptr;
  {
    KeptWarnings warnings;
    model = mj_loadXML(path.c_str(), nullptr, text, sizeof text);
    for (const std::string& w : warnings.list) {
      std::cerr << "warning: " << path << ": " << w << '\n';
    }
  }
  error = text;
  return model;
}

MujocoModel load_mujoco_model(const std::string& path) {
  check_input_file(path, kMaxMediaFileBytes);
  std::string error;
  mjModel* raw = read_mjcf(path, error);
  if (!raw) {
    std::string message = error;
    // MuJoCo's parser errors say "... line N ..."; take N for the location.
    int line = 0;
    if (const auto at = message.find("line "); at != std::string::npos) {
      line = std::atoi(message.c_str() + at + 5);
    }
    for (auto& c : message) {
      if (c == '\n') c = ' ';
    }
    throw InputError({path, line, 0}, "", "invalid MJCF model: " + message);
  }
  MujocoModel out;
  out.model = std::shared_ptr<const mjModel>(
      raw, [](const mjModel* m) { mj_deleteModel(const_cast<mjModel*>(m)); });
  out.file = path;
  const mjModel* m = raw;
  check_mujoco_timestep(*m, path);
  out.torso_body = mj_name2id(m, mjOBJ_BODY, "torso");
  if (out.torso_body < 0)
    throw InputError({path, 0, 0}, "torso", "the model needs a body named torso");
  for (int g = 0; g < m->ngeom; ++g) {
    const char* name = mj_id2name(m, mjOBJ_GEOM, g);
    if (!name) continue;
    const std::string n = name;
    if (n.size() >= 4 && n.compare(n.size() - 4, 4, "foot") == 0) out.foot_geoms.push_back(g);
  }
  if (out.foot_geoms.empty()) {
    throw InputError({path, 0, 0}, "foot", "the model needs geoms whose names end in 'foot'");
  }
  for (int a = 0; a < m->nu; ++a) {
    if (m->actuator_trntype[a] != mjTRN_JOINT) {
      throw InputError({path, 0, 0}, "actuator", "every actuator must drive a joint");
    }
    const int j = m->actuator_trnid[2 * a];
    if (m->jnt_type[j] != mjJNT_HINGE) {
      throw InputError({path, 0, 0}, "actuator", "every actuator must drive a hinge joint");
    }
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    out.actuated_joints.push_back(name ? name : "");
    out.actuator_qpos.push_back(m->jnt_qposadr[j]);
    out.actuator_dof.push_back(m->jnt_dofadr[j]);
  }
  const int hh = mj_name2id(m, mjOBJ_NUMERIC, "hip_height");
  out.hip_height_m =
      hh >= 0 ? m->numeric_data[m->numeric_adr[hh]] : m->body_pos[3 * out.torso_body + 2];
  out.mass_kg = mj_getTotalmass(m);
  return out;
}

MujocoData make_mujoco_data(const MujocoModel& model) {
  mjData* d = mj_makeData(model.model.get());
  if (!d) throw std::runtime_error("mj_makeData failed for " + model.file);
  return MujocoData(d, mj_deleteData);
}

}  // namespace animrt::sim
