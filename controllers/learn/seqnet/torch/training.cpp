#include "animrt/learn/seqnet/training.hpp"

#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <random>
#include <sstream>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/controllers/seqnet/joint_csv.hpp"
#include "animrt/controllers/seqnet/placement_nodes.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/blas_kernels.hpp"
#include "animrt/learn/seqnet/held_out.hpp"
#include "animrt/learn/seqnet/held_out_completion.hpp"
#include "animrt/learn/seqnet/network.hpp"

namespace animrt::seqnet {
namespace {

[[noreturn]] void fail(const std::string& file, int line, int column, const std::string& key,
                       const std::string& message) {
  throw InputError(Location{file, line, column}, key, message);
}

// Cuts the frames [first, first + count) of one clip into training and
// held-out segments.
void add_clip(TrainingSet& set, int dataset, const std::vector<std::vector<float>>& frames,
              int first, int count, std::pair<int, int> block) {
  int start = first;
  const int end = first + count;
  while (start < end) {
    const bool held = start >= block.first && start < block.first + block.second;
    int stop = start;
    while (stop < end && (stop >= block.first && stop < block.first + block.second) == held) {
      ++stop;
    }
    Segment s;
    s.dataset = dataset;
    s.held_out = held;
    s.first = start;
    s.count = stop - start;
    for (int f = start; f < stop; ++f) {
      const auto& v = frames[static_cast<std::size_t>(f)];
      s.values.insert(s.values.end(), v.begin(), v.end());
    }
    set.segments.push_back(std::move(s));
    start = stop;
  }
}

bool listed(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string duration(double seconds) {
  const auto s = static_cast<long>(std::lround(std::max(0.0, seconds)));
  char buf[32];
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  }
  return buf;
}

LossRecord record(const LossTerms& l) {
  return {l.recon.item<double>(), l.bidir.item<double>(), l.kl.item<double>(), l.l2.item<double>(),
          l.total.item<double>()};
}

std::vector<std::string> parameter_names(const SeqNetImpl& net) {
  std::vector<std::string> names;
  for (const auto& item : net.named_parameters()) names.push_back(item.key());
  return names;
}

// A fraction as a percentage with two decimals: "3.49 %".
std::string percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f %%", 100.0 * fraction);
  return text;
}

// "held out at iteration 200: completion of 9-frame gaps 2.30 %, linear
// interpolation 1.39 % (65 % worse than interpolation)", then for mesh data
// with its placement "; placed vertices 1.90 % of the diagonal, linear
// vertex interpolation 3.49 % (46 % better)".
std::string held_out_line(const HeldOutCompletion& h, int iteration) {
  if (h.gaps == 0) {
    return "held out at iteration " + std::to_string(iteration) +
           ": no held-out piece is long enough to complete a gap";
  }
  if (h.network < 0) {
    return "held out at iteration " + std::to_string(iteration) +
           ": the model's completion is not finite";
  }
  std::string line = "held out at iteration " + std::to_string(iteration) + ": completion of " +
                     std::to_string(h.gap) + "-frame gaps " + percent(h.network) +
                     ", linear interpolation " + percent(h.interpolation) + " (" +
                     compared_with(h.network, h.interpolation) + " than interpolation)";
  if (h.placed >= 0) {
    line += "; placed vertices " + percent(h.placed) + " of the diagonal, linear vertex " +
            "interpolation " + percent(h.placed_interpolation) + " (" +
            compared_with(h.placed, h.placed_interpolation) + ")";
  }
  return line;
}

// The placement nodes' numbers (placement_nodes.hpp) after every frame's
// features, each mapped from its range to [-0.95, 0.95] as the features
// are. A feature file without placement (version 1) gets none.
void append_placement(ModelFile& d, const SequenceFeatures& f,
                      std::vector<std::vector<float>>& frames) {
  const std::vector<Eigen::VectorXd> track = placement_track(f);
  if (track.empty()) return;
  const Eigen::Index n = track.front().size();
  d.shape.placement_nodes = static_cast<int>(n / 9);
  Eigen::VectorXd low = track.front(), high = track.front();
  for (const Eigen::VectorXd& v : track) {
    low = low.cwiseMin(v);
    high = high.cwiseMax(v);
  }
  d.low.insert(d.low.end(), low.data(), low.data() + n);
  d.high.insert(d.high.end(), high.data(), high.data() + n);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const double span = high[i] - low[i];
      frames[k].push_back(span > 0 ? static_cast<float>((track[k][i] - low[i]) / span * 1.9 - 0.95)
                                   : 0.0F);
    }
  }
}

// Why the model in `kept` is not one of the training that makes `now`
// (another data kind, joint set or mesh, network, seed and so held-out
// split, or feature mapping): its held-out figure would not compare with
// this training's. Empty when it is one.
std::string not_of_this_training(const ModelFile& kept, const ModelFile& now,
                                 const std::string& file) {
  try {
    if (now.shape.kind == ModelKind::mesh) {
      check_model_mesh(kept, file, now.shape.vertex_count, now.triangles);
    } else {
      check_model_joints(kept, file, now.joint_names);
    }
  } catch (const InputError& e) {
    return e.message();
  }
  const NetShape& a = kept.shape;
  const NetShape& b = now.shape;
  const bool mesh = b.kind == ModelKind::mesh;
  const std::pair<const char*, std::pair<double, double>> sizes[] = {
      {"placement nodes", {a.placement_nodes, b.placement_nodes}},
      {"encoder layers", {a.conv_layers, b.conv_layers}},
      {"channels", {mesh ? a.channels : 0, mesh ? b.channels : 0}},
      {"dense width", {mesh ? 0 : a.dense_width, mesh ? 0 : b.dense_width}},
      {"latent", {a.latent, b.latent}},
      {"hidden", {a.hidden, b.hidden}},
      {"LSTM layers", {a.lstm_layers, b.lstm_layers}},
      {"window", {a.window, b.window}},
      {"stride", {a.stride, b.stride}},
      {"s0", {a.s0, b.s0}}};
  std::string network;
  for (const auto& [name, values] : sizes) {
    if (values.first == values.second) continue;
    std::ostringstream d;
    d << (network.empty() ? "" : ", ") << name << ' ' << values.first << " against "
      << values.second;
    network += d.str();
  }
  if (!network.empty()) return "another network (" + network + ")";
  if (kept.seed != now.seed) {
    return "trained from seed " + std::to_string(kept.seed) + ", this training from seed " +
           std::to_string(now.seed) + " (another held-out split)";
  }
  if (kept.low != now.low || kept.high != now.high || kept.rest.cols() != now.rest.cols() ||
      kept.rest != now.rest) {
    return "another feature mapping or template (fitted to other data)";
  }
  return {};
}

}  // namespace

TrainingSet load_training_set(const std::vector<std::string>& files, std::uint64_t seed,
                              double held_out, const std::vector<std::string>& held_out_clips) {
  if (files.empty()) throw InputError(Location{}, "DATA", "no data files given");
  TrainingSet set;
  set.sources = files;
  const bool csv =
      files.front().size() >= 4 && files.front().compare(files.front().size() - 4, 4, ".csv") == 0;
  if (!csv) {
    if (files.size() != 1) {
      fail(files[1], 0, 0, "DATA",
           "mesh training takes one feature file (joint CSVs may be several)");
    }
    const SequenceFeatures f = read_feature_file(files.front());
    set.kind = ModelKind::mesh;
    ModelFile& d = set.description;
    d.shape.kind = ModelKind::mesh;
    d.shape.vertex_count = f.vertex_count();
    d.rest = f.rest;
    d.triangles = f.triangles;
    d.low.assign(f.scale.low.data(), f.scale.low.data() + f.scale.low.size());
    d.high.assign(f.scale.high.data(), f.scale.high.data() + f.scale.high.size());
    std::vector<std::vector<float>> frames;
    for (const FeatureFrame& frame : f.frames) {
      frames.emplace_back(frame.data(), frame.data() + frame.size());
    }
    append_placement(d, f, frames);
    set.dims = d.shape.input_dims();
    const int n = static_cast<int>(frames.size());
    std::vector<Clip> clips = f.clips;
    if (clips.empty()) clips.push_back(Clip{"all", 0, n, 0.0});
    std::vector<std::string> names;
    for (const Clip& c : clips) names.push_back(c.name);
    check_clip_names(held_out_clips, names, files.front());
    const auto block =
        held_out_clips.empty() ? held_out_block(n, held_out, seed, 0) : std::pair<int, int>{0, 0};
    for (const Clip& c : clips) {
      add_clip(set, 0, frames, c.first, c.count,
               listed(held_out_clips, c.name) ? std::pair<int, int>{c.first, c.count} : block);
    }
    if (!f.placement.empty()) {
      const Reconstructor solver(f.rest, f.triangles);
      for (Segment& s : set.segments) {
        if (!s.held_out) continue;
        for (int k = s.first; k < s.first + s.count; ++k) {
          s.placed.push_back(reconstruct_frame(solver, f, k));
        }
      }
    }
    return set;
  }
  set.kind = ModelKind::joints;
  std::vector<std::vector<std::vector<double>>> per_file;
  std::vector<std::string> joints;
  check_clip_names(held_out_clips, files, files.front());
  for (std::size_t k = 0; k < files.size(); ++k) {
    JointCsv t = read_joint_csv(files[k]);
    if (k == 0) {
      joints = t.joints;
    } else if (t.joints != joints) {
      fail(files[k], 1, 1, "", "joint columns differ from those of " + files[0]);
    }
    std::vector<std::vector<double>> rows = std::move(t.rows);
    per_file.push_back(std::move(rows));
  }
  const std::size_t j = joints.size();
  ModelFile& d = set.description;
  d.shape.kind = ModelKind::joints;
  d.shape.joint_count = static_cast<int>(j);
  d.joint_names = joints;
  d.low.assign(j, 0.0);
  d.high.assign(j, 0.0);
  bool first = true;
  for (const auto& rows : per_file) {
    for (const auto& r : rows) {
      for (std::size_t c = 0; c < j; ++c) {
        d.low[c] = first ? r[c] : std::min(d.low[c], r[c]);
        d.high[c] = first ? r[c] : std::max(d.high[c], r[c]);
      }
      first = false;
    }
  }
  set.dims = static_cast<int>(j);
  for (std::size_t k = 0; k < per_file.size(); ++k) {
    std::vector<std::vector<float>> frames;
    for (const auto& r : per_file[k]) {
      std::vector<float> v(j);
      for (std::size_t c = 0; c < j; ++c) {
        const double span = d.high[c] - d.low[c];
        v[c] = span > 0 ? static_cast<float>((r[c] - d.low[c]) / span * 1.9 - 0.95) : 0.0F;
      }
      frames.push_back(std::move(v));
    }
    const int n = static_cast<int>(frames.size());
    const auto block = held_out_clips.empty()
                           ? held_out_block(n, held_out, seed, static_cast<int>(k))
                           : std::pair<int, int>{0, listed(held_out_clips, files[k]) ? n : 0};
    add_clip(set, static_cast<int>(k), frames, 0, n, block);
  }
  return set;
}

std::string loss_plot_svg(const std::vector<LossRecord>& history) {
  const double w = 800, h = 420, left = 70, right = 150, top = 20, bottom = 50;
  double lo = 1e30, hi = -1e30;
  auto terms = [](const LossRecord& r) {
    return std::array<double, 5>{r.total, r.recon, r.bidir, r.kl, r.l2};
  };
  for (const auto& r : history) {
    for (double v : terms(r)) {
      if (v > 0) {
        lo = std::min(lo, std::log10(v));
        hi = std::max(hi, std::log10(v));
      }
    }
  }
  if (lo > hi) lo = hi = 0;
  lo = std::floor(lo);
  hi = std::max(lo + 1, std::ceil(hi));
  const double n = std::max<double>(1, static_cast<double>(history.size()) - 1);
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  const double pw = w - left - right, ph = h - top - bottom;
  s << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
    << "\" fill=\"none\" stroke=\"black\"/>\n";
  for (double e = lo; e <= hi; e += 1) {
    const double y = top + ph * (hi - e) / (hi - lo);
    s << "<line x1=\"" << left << "\" x2=\"" << left + pw << "\" y1=\"" << y << "\" y2=\"" << y
      << "\" stroke=\"#ddd\"/><text x=\"" << left - 8 << "\" y=\"" << y + 4
      << "\" text-anchor=\"end\">1e" << e << "</text>\n";
  }
  s << "<text x=\"" << left + pw / 2 << "\" y=\"" << h - 15
    << "\" text-anchor=\"middle\">iteration (" << history.size() << ")</text>\n";
  const char* names[] = {"total", "recon", "bidir", "KL", "L2"};
  const char* colours[] = {"black", "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728"};
  for (int k = 0; k < 5; ++k) {
    s << "<polyline fill=\"none\" stroke=\"" << colours[k] << "\" points=\"";
    for (std::size_t i = 0; i < history.size(); ++i) {
      const double v = terms(history[i])[static_cast<std::size_t>(k)];
      if (!(v > 0)) continue;
      const double x = left + pw * static_cast<double>(i) / n;
      const double y = top + ph * (hi - std::log10(v)) / (hi - lo);
      s << x << ',' << y << ' ';
    }
    s << "\"/>\n<text x=\"" << left + pw + 10 << "\" y=\"" << top + 20 + 18 * k << "\" fill=\""
      << colours[k] << "\">" << names[k] << "</text>\n";
  }
  s << "</svg>\n";
  return s.str();
}

TrainResult train(const TrainOptions& o, std::ostream& progress) {
  torch::set_num_threads(std::max(1, o.threads));
  ModelFile checkpoint;
  const bool resuming = !o.resume.empty();
  if (resuming) checkpoint = read_model_file(o.resume);
  const std::uint64_t seed = resuming ? checkpoint.seed : o.seed;
  TrainingSet set = load_training_set(o.data, seed, o.held_out, o.held_out_clips);
  NetShape shape = set.description.shape;
  if (resuming) {
    if (set.kind == ModelKind::mesh) {
      check_model_mesh(checkpoint, o.resume, shape.vertex_count, set.description.triangles);
    } else {
      check_model_joints(checkpoint, o.resume, set.description.joint_names);
    }
    if (checkpoint.shape.placement_nodes != shape.placement_nodes) {
      fail(o.resume, 0, 0, "shape",
           "a checkpoint with " + std::to_string(checkpoint.shape.placement_nodes) +
               " placement nodes, the data has " + std::to_string(shape.placement_nodes) +
               " (a checkpoint of an older build): start a new training without --resume");
    }
    if (checkpoint.optimiser.empty()) {
      fail(o.resume, 0, 0, "optimiser", "a final model, not a checkpoint (no optimiser state)");
    }
    shape = checkpoint.shape;
  } else {
    shape.latent = o.latent;
    shape.hidden = o.hidden;
    shape.lstm_layers = o.lstm_layers;
    shape.channels = o.channels;
    shape.dense_width = o.dense_width;
    shape.window = o.window;
    shape.stride = o.stride;
  }
  if (o.placement_weight != 1.0 && shape.placement_nodes == 0) {
    fail(o.data.front(), 0, 0, "placement weight",
         "the data has no placement numbers to weigh (mesh feature files carry them)");
  }
  const torch::Tensor frame_weight =
      frame_weights(set.dims, 9 * shape.placement_nodes, o.placement_weight);
  const int span = (shape.window - 1) * shape.stride + 1;
  int longest = 0;
  std::vector<std::size_t> usable;
  std::vector<double> starts;
  for (std::size_t k = 0; k < set.segments.size(); ++k) {
    const Segment& s = set.segments[k];
    if (s.held_out) continue;
    longest = std::max(longest, s.count);
    if (s.count >= span) {
      usable.push_back(k);
      starts.push_back(s.count - span + 1);
    }
  }
  if (usable.empty()) {
    fail(o.data.front(), 0, 0, "window",
         "no training piece has " + std::to_string(span) + " frames (window " +
             std::to_string(shape.window) + ", stride " + std::to_string(shape.stride) +
             "); the longest has " + std::to_string(longest));
  }

  torch::manual_seed(seed);
  MeshGraph graph;
  if (shape.kind == ModelKind::mesh)
    graph = mesh_graph(shape.vertex_count, set.description.triangles);
  SeqNet net(shape, graph);
  if (o.zero_output) net->zero_output_layer();  // a resume loads over it
  const std::vector<std::string> names = parameter_names(*net);
  Adam adam(net->parameters(), o.learning_rate);
  std::vector<LossRecord> history;
  int iteration = 0;
  if (resuming) {
    load_parameters(*net, checkpoint.parameters, o.resume);
    std::vector<NamedArray> state;
    for (const NamedArray& a : checkpoint.optimiser) {
      if (a.name == "history") {
        if (a.shape.size() != 2 || a.shape[1] != 5) {
          fail(o.resume, 0, 0, "optimiser history", "expected N x 5 values");
        }
        for (std::size_t i = 0; i < static_cast<std::size_t>(a.shape[0]); ++i) {
          const float* v = &a.values[i * 5];
          history.push_back({v[0], v[1], v[2], v[3], v[4]});
        }
      } else {
        state.push_back(a);
      }
    }
    adam.restore(state, names, o.resume);
    iteration = static_cast<int>(checkpoint.iteration);
    if (static_cast<int>(checkpoint.threads) != o.threads) {
      progress << "note: the checkpoint was trained with " << checkpoint.threads
               << " threads, this run uses " << o.threads
               << ": the result will not repeat a single run bit for bit\n";
    }
  }

  HeldOutCompletion measured;
  auto model_file = [&](bool with_state) {
    ModelFile m = set.description;
    m.shape = shape;
    m.seed = seed;
    m.threads = static_cast<std::uint32_t>(o.threads);
    m.iteration = static_cast<std::uint64_t>(iteration);
    m.parameters = save_parameters(*net);
    m.held_out_completion = measured.network;
    m.held_out_interpolation = measured.interpolation;
    m.held_out_gap = measured.gap;
    if (with_state) {
      m.optimiser = adam.state(names);
      NamedArray h;
      h.name = "history";
      h.shape = {static_cast<std::int64_t>(history.size()), 5};
      for (const auto& r : history) {
        for (double v : {r.total, r.recon, r.bidir, r.kl, r.l2}) {
          h.values.push_back(static_cast<float>(v));
        }
      }
      if (!history.empty()) m.optimiser.push_back(std::move(h));
    }
    return m;
  };
  auto write_plot = [&] {
    std::ofstream svg(o.out + ".svg", std::ios::trunc);
    if (!svg) throw std::runtime_error(o.out + ".svg: cannot write");
    svg << loss_plot_svg(history);
  };
  auto held_out_loss = [&]() -> double {
    torch::NoGradGuard no_grad;
    double sum = 0;
    int count = 0;
    for (const Segment& s : set.segments) {
      if (!s.held_out || s.count < 2) continue;
      const int n = std::min(shape.window, (s.count - 1) / shape.stride + 1);
      std::vector<float> values;
      for (int f = 0; f < n; ++f) {
        const auto* row = &s.values[static_cast<std::size_t>(f * shape.stride) *
                                    static_cast<std::size_t>(set.dims)];
        values.insert(values.end(), row, row + set.dims);
      }
      const torch::Tensor truth =
          torch::from_blob(values.data(), {n, 1, set.dims}, torch::kFloat32).clone();
      sum += batch_loss(net, truth, false).recon.item<double>() / n;
      ++count;
    }
    return count == 0 ? -1.0 : sum / count;
  };

  // OUT.best keeps the model of the best held-out measurement so far, so a
  // training that runs on past its best (or is thrown off by one batch)
  // still leaves it. Placed vertices decide where they are measured. A
  // resumed run first measures the OUT.best it finds, on this data; one
  // that cannot be read or measured, or is of another training, is moved
  // to OUT.best.stale (kept for the user, not compared) and the run goes on.
  const std::string best_path = o.out + ".best";
  auto score = [](const HeldOutCompletion& h) {
    return h.placed >= 0 ? h.placed : h.network;
  };
  double best_score = -1;
  TrainResult result;
  std::error_code no_best;
  if (resuming && std::filesystem::exists(best_path, no_best)) {
    std::string why;
    try {
      const ModelFile kept = read_model_file(best_path);
      why = not_of_this_training(kept, model_file(false), best_path);
      if (why.empty()) {
        best_score = score(measure_held_out_completion(kept, set, 9, o.blend));
        if (best_score >= 0) result.kept_best_iteration = static_cast<int>(kept.iteration);
      }
    } catch (const InputError& e) {
      why = "cannot be read: " + (e.key().empty() ? "" : e.key() + ": ") + e.message();
    } catch (const std::exception& e) {
      why = std::string("cannot be measured: ") + e.what();
    }
    if (!why.empty()) {
      const std::string stale = best_path + ".stale";
      std::error_code error;
      std::filesystem::rename(best_path, stale, error);
      progress << "note: " << best_path << " is not a best model of this training: " << why
               << (error ? "; it cannot be moved (" + error.message() +
                               "), the first held-out measurement replaces it"
                         : "; moved to " + stale)
               << '\n';
    }
  }
  auto measure = [&] {
    measured = HeldOutCompletion{};
    ModelFile now = model_file(false);
    measured = measure_held_out_completion(now, set, 9, o.blend);
    progress << held_out_line(measured, iteration) << std::endl;
    const double s = score(measured);
    if (s >= 0 && (best_score < 0 || s < best_score)) {
      best_score = s;
      now.held_out_completion = measured.network;
      now.held_out_interpolation = measured.interpolation;
      now.held_out_gap = measured.gap;
      write_model_file(best_path, now);
      result.best_iteration = iteration;
      result.kept_best_iteration = -1;
    }
  };

  // Said once the data and checkpoint are accepted (an error stays one line).
  const std::string kernels = blas_kernels();
  progress << "libtorch threads " << torch::get_num_threads() << ", BLAS kernels "
           << (kernels.empty() ? "not OpenBLAS" : kernels) << '\n';
  const auto t0 = std::chrono::steady_clock::now();
  const int first_iteration = iteration;
  std::discrete_distribution<std::size_t> pick(starts.begin(), starts.end());
  while (iteration < o.iterations) {
    // Batch and latent noise depend on the seed and the iteration only, so
    // a resumed run draws what an uninterrupted one would.
    std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + static_cast<std::uint64_t>(iteration));
    torch::manual_seed(seed * 1000003ULL + static_cast<std::uint64_t>(iteration));
    std::vector<float> values(static_cast<std::size_t>(shape.window) *
                              static_cast<std::size_t>(o.batch) *
                              static_cast<std::size_t>(set.dims));
    for (int b = 0; b < o.batch; ++b) {
      const std::size_t k = pick(rng);
      const Segment& s = set.segments[usable[k]];
      const int start = std::uniform_int_distribution<int>(0, s.count - span)(rng);
      for (int f = 0; f < shape.window; ++f) {
        const float* row = &s.values[static_cast<std::size_t>(start + f * shape.stride) *
                                     static_cast<std::size_t>(set.dims)];
        std::copy(row, row + set.dims,
                  &values[(static_cast<std::size_t>(f) * static_cast<std::size_t>(o.batch) +
                           static_cast<std::size_t>(b)) *
                          static_cast<std::size_t>(set.dims)]);
      }
    }
    const torch::Tensor truth =
        torch::from_blob(values.data(), {shape.window, o.batch, set.dims}, torch::kFloat32);
    const LossTerms l = train_step(net, adam, truth, o.kl_weight, o.bidirectional, o.l2_weight,
                                     frame_weight, o.clip_gradient);
    ++iteration;
    if (o.clip_gradient > 0) {
      if (l.gradient_norm > o.clip_gradient) ++result.clipped;
      result.largest_gradient_norm = std::max(result.largest_gradient_norm, l.gradient_norm);
    }
    result.last = record(l);
    if (!std::isfinite(result.last.total)) {
      throw std::runtime_error("training diverged at iteration " + std::to_string(iteration) +
                               " (loss is not finite); try a lower learning rate");
    }
    history.push_back(result.last);
    const bool last = iteration == o.iterations;
    if (o.report_every > 0 && (iteration % o.report_every == 0 || last)) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double rate = (iteration - first_iteration) / std::max(elapsed, 1e-9);
      char line[256];
      std::snprintf(line, sizeof line,
                    "iteration %d/%d  recon %.4g  bidir %.4g  KL %.4g  L2 %.4g  total %.4g  "
                    "%.2f it/s  left %s",
                    iteration, o.iterations, result.last.recon, result.last.bidir, result.last.kl,
                    result.last.l2, result.last.total, rate,
                    duration((o.iterations - iteration) / rate).c_str());
      progress << line << std::endl;
    }
    if (last || (o.held_out_every > 0 && iteration % o.held_out_every == 0)) measure();
    if (o.checkpoint_every > 0 && (iteration % o.checkpoint_every == 0 || last)) {
      write_model_file(o.out + ".ckpt", model_file(true));
      write_plot();
    }
  }
  if (iteration == first_iteration) measure();  // nothing left to train: measured as it is
  result.held_out = held_out_loss();
  result.held_out_completion = measured.network;
  result.held_out_interpolation = measured.interpolation;
  write_model_file(o.out, model_file(false));
  write_plot();
  result.iterations = iteration;
  result.run = iteration - first_iteration;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (result.held_out >= 0) {
    progress << "held-out reconstruction loss per frame " << result.held_out << '\n';
  } else {
    progress << "held-out reconstruction loss: no held-out piece of 2 frames or more\n";
  }
  if (o.clip_gradient > 0) {
    progress << "gradient clipped to " << o.clip_gradient << " in " << result.clipped << " of "
             << result.run << " iterations (largest norm " << result.largest_gradient_norm
             << ")\n";
  }
  if (result.best_iteration > 0) {
    progress << "best held-out completion: iteration " << result.best_iteration << ", kept in "
             << best_path << '\n';
  } else if (result.kept_best_iteration >= 0) {
    progress << "best held-out completion: iteration " << result.kept_best_iteration
             << " (an earlier run), kept in " << best_path << '\n';
  }
  progress << "model " << o.out << ", checkpoint " << o.out << ".ckpt, loss plot " << o.out
           << ".svg\n";
  return result;
}

}  // namespace animrt::seqnet
