// The corpus: schedule, presets and files (see generator.hpp).

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/seq_corpus/generator.hpp"

namespace animrt::learn::seq_corpus {
namespace {

namespace fs = std::filesystem;

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

// A YAML double-quoted scalar.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + path);
}

std::string body_name(const mjModel* m, int b) {
  const char* name = mj_id2name(m, mjOBJ_BODY, b);
  return name ? name : "body" + std::to_string(b);
}

}  // namespace

std::string sequence_name(const WalkConfig& c) {
  return fs::path(c.gait_file).stem().string() + "_fr" + fixed(c.froude, 3) + "_turn" +
         fixed(c.turn_rad_s, 2) + "_seed" + std::to_string(c.seed);
}

std::vector<WalkConfig> corpus_schedule(const CorpusOptions& o) {
  std::vector<WalkConfig> out;
  for (const auto& gait : o.gaits)
    for (double fr : o.froude)
      for (double turn : o.turns)
        for (int s = 0; s < o.seeds; ++s)
          out.push_back({gait, fr, o.first_seed + static_cast<std::uint64_t>(s), turn});
  return out;
}

CorpusOptions model_preset(const std::string& name, const std::string& configs_dir) {
  const fs::path root(configs_dir);
  CorpusOptions o;
  if (name == "horse") {
    o.model_file = (root / "models/horse.xml").string();
    o.gaits = {(root / "gaits/horse_seed.yaml").string()};
    o.froude = {0.35, 0.4, 0.45};  // around the seed gait's 0.4
  } else if (name == "quadruped") {
    o.model_file = (root / "models/quadruped.xml").string();
    o.gaits = {(root / "gaits/walk.yaml").string(),
               (root / "gaits/quadruped_evolved.yaml").string()};
    o.froude = {0.04, 0.06, 0.08};  // walk.yaml's 1 Hz is Fr 0.054, the evolved gait's 0.06
  } else {
    throw std::invalid_argument("no preset for model '" + elide(name) + "' (horse, quadruped)");
  }
  return o;
}

void write_joints_csv(const std::string& path, const MujocoModel& model, const WalkRecord& walk) {
  std::string text = "time_s";
  for (const auto& j : model.actuated_joints) text += "," + j;
  text += ",torso_x,torso_y,torso_z,torso_yaw\n";
  for (std::size_t f = 0; f < walk.time_s.size(); ++f) {
    text += fixed(walk.time_s[f], 4);
    for (double q : walk.joints[f]) text += "," + fixed(q, 6);
    for (double x : walk.torso[f]) text += "," + fixed(x, 6);
    text += '\n';
  }
  write_text(path, text);
}

CorpusSummary generate_corpus(const std::string& dir, const CorpusOptions& o) {
  const auto log = [&o](const std::string& s) {
    if (o.log) o.log(s);
  };
  if (o.gaits.empty() || o.froude.empty() || o.turns.empty() || o.seeds < 1)
    throw std::invalid_argument("the corpus needs a gait, a Froude number, a turn and a seed");
  const MujocoModel model = load_mujoco_model(o.model_file);
  const mjModel* m = model.model.get();
  physics_steps_per_frame(model, o.walk);  // before any work
  const Skin skin = bind_pose_skin(model, o.vertices);
  fs::create_directories(dir);
  const fs::path root(dir);

  CorpusSummary summary;
  summary.vertices = static_cast<int>(skin.rest.vertices.cols());
  summary.triangles = static_cast<int>(skin.rest.triangles.size());
  log("skin: " + std::to_string(summary.vertices) + " vertices, " +
      std::to_string(summary.triangles) + " triangles (grid step " +
      fixed(skin.grid_step_m * 1000.0, 1) + " mm)");
  seqnet::MeshSequence rest;
  rest.triangles = skin.rest.triangles;
  rest.frames.push_back(skin.rest.vertices);
  seqnet::write_obj((root / "rest.obj").string(), rest, 0);
  std::string weights = "vertex,body,weight\n";
  for (std::size_t v = 0; v < skin.weights.size(); ++v) {
    for (int i = 0; i < kInfluences; ++i) {
      const double w = skin.weights[v][static_cast<std::size_t>(i)];
      if (w == 0.0) continue;
      weights += std::to_string(v) + "," +
                 body_name(m, skin.bodies[v][static_cast<std::size_t>(i)]) + "," + fixed(w, 6) +
                 "\n";
    }
  }
  write_text((root / "skin_weights.csv").string(), weights);

  std::string index = "# Generated mesh sequence corpus (docs/seqnet.md, \"Generated corpus\").\n";
  index += "model: " + quoted(o.model_file) + "\n";
  index += "fps: " + number(o.walk.fps) + "\n";
  index += "frames_requested: " + std::to_string(o.walk.frames) + "\n";
  index += "vertices: " + std::to_string(summary.vertices) + "\n";
  index += "triangles: " + std::to_string(summary.triangles) + "\n";
  index += "rest_mesh: rest.obj\nskin_weights: skin_weights.csv\n";
  index += "joints: [";
  for (std::size_t j = 0; j < model.actuated_joints.size(); ++j)
    index += (j ? ", " : "") + quoted(model.actuated_joints[j]);
  index += "]\nsequences:\n";
  for (const WalkConfig& c : corpus_schedule(o)) {
    const std::string name = sequence_name(c);
    const WalkRecord walk = walk_sequence(model, skin, c, o.walk);
    seqnet::write_obj_sequence((root / name).string(), walk.mesh);
    write_joints_csv((root / (name + ".csv")).string(), model, walk);
    ++summary.sequences;
    summary.fell += walk.fell ? 1 : 0;
    summary.frames += walk.mesh.frame_count();
    index += "  - name: " + quoted(name) + "\n";
    index += "    folder: " + quoted(name) + "\n";
    index += "    joints_csv: " + quoted(name + ".csv") + "\n";
    index += "    gait: " + quoted(c.gait_file) + "\n";
    index += "    froude: " + number(c.froude) + "\n";
    index += "    froude_actual: " + number(walk.timing.froude) + "\n";
    index += "    seed: " + std::to_string(c.seed) + "\n";
    index += "    start_phase: " + number(walk.timing.start_phase) + "\n";
    index += "    turn_rad_s: " + number(c.turn_rad_s) + "\n";
    index += "    frames: " + std::to_string(walk.mesh.frame_count()) + "\n";
    index += "    vertices: " + std::to_string(walk.mesh.vertex_count()) + "\n";
    index += "    fell: " + std::string(walk.fell ? "true" : "false") + "\n";
    index += "    achieved_speed_m_s: " + fixed(walk.speed_m_s, 4) + "\n";
    index += "    achieved_turn_rad_s: " + fixed(walk.turn_rad_s, 4) + "\n";
    log(name + ": " + std::to_string(walk.mesh.frame_count()) + " frames, " +
        fixed(walk.speed_m_s, 3) + " m/s" + (walk.fell ? ", fell" : ""));
  }
  write_text((root / "index.yaml").string(), index);
  return summary;
}

}  // namespace animrt::learn::seq_corpus
