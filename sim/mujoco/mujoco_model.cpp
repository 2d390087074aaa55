// Loading and checking MJCF models (see mujoco_model.hpp).

#include "animrt/sim/mujoco/mujoco_model.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>

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

MujocoModel load_mujoco_model(const std::string& path) {
  check_input_file(path, kMaxMediaFileBytes);
  char error[1024] = "";
  mjModel* raw = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
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
