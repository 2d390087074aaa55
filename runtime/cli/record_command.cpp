#include "record_command.hpp"

#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "animrt/controllers/show/key_reducer.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "limp_figure.hpp"
#include "option_checks.hpp"
#include "sound_track_recorder.hpp"
#include "stop_signals.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
// Named, so that the unity build's other commands do not share these names.
namespace record_cmd {

struct RecordArgs {
  std::string robot;
  std::string out;
  double tolerance_deg = 0.5;
  double duration_s = 0.0;
  std::vector<std::string> joints;
  PortOverrides ports;
  bool audio = false;
  std::string audio_device = "default";
  double compliant_percent = 0.0;  // 0: limp
};

// A compliant joint's goal follows the hand once it is pushed this far from
// it; closer, the weak torque holds the goal against the figure's weight.
constexpr double kFollowHandRad = 0.5 * std::numbers::pi / 180.0;

// The joints held by a weak torque: their goals, NaN for the limp ones.
struct Hold {
  std::vector<double> goals;
  bool any = false;
  // After a read: a goal pushed past kFollowHandRad moves to where the hand put it.
  void follow(const std::vector<double>& positions, const std::vector<bool>& fresh) {
    for (std::size_t j = 0; j < goals.size(); ++j) {
      if (std::isnan(goals[j]) || !fresh[j]) continue;
      if (std::abs(positions[j] - goals[j]) > kFollowHandRad) goals[j] = positions[j];
    }
  }
};

constexpr int kSoundTrackRate = 48000;

// Keys are written to 0.001 of the joint's unit: the rounding
// is taken off the bound the reducer keeps.
constexpr double kValueQuantum = 0.001;
// Key times are written to 0.1 ms: samples closer than this would collide.
constexpr double kMinSampleGap = 0.0002;

std::string number(double value, int decimals) {
  const double scale = std::pow(10.0, decimals);
  double r = std::round(value * scale) / scale;
  if (r == 0.0) r = 0.0;
  return fmt::format("{}", r);
}

struct Track {
  std::size_t joint;
  std::string name;
  bool prismatic;
  std::vector<double> times;   // s since the recording began
  std::vector<double> values;  // deg or m
};

// The show must be writable before anything is recorded.
void check_writable(const std::string& out) {
  const bool existed = std::filesystem::exists(out);
  std::ofstream probe(out, std::ios::app);
  if (!probe) throw std::invalid_argument("--out: cannot write " + quote_path(out));
  probe.close();
  if (!existed) std::filesystem::remove(out);
}

// The tracks to record: the joints asked for (all by default) that are on a bus.
std::vector<Track> choose_tracks(const RecordArgs& args, const LimpFigure& figure) {
  const RobotConfig& config = figure.config();
  std::vector<Track> tracks;
  for (std::size_t j = 0; j < config.joints.size(); ++j) {
    const JointSpec& spec = config.joints[j];
    const bool asked = args.joints.empty() || std::find(args.joints.begin(), args.joints.end(),
                                                        spec.name) != args.joints.end();
    if (!asked || figure.binding(j) == nullptr) continue;
    tracks.push_back({j, spec.name, spec.type == JointType::prismatic, {}, {}});
  }
  for (const std::string& name : args.joints) {
    if (std::none_of(tracks.begin(), tracks.end(),
                     [&](const Track& t) { return t.name == name; })) {
      throw std::invalid_argument("--joint " + quote(name) + ": the robot file " +
                                  quote_path(config.file) + " has no joint of that name on a bus");
    }
  }
  return tracks;
}

struct Sampling {
  timespec start{};
  std::size_t reads = 0;
  double last_t = 0.0;
  std::size_t missed = 0;
};

// Reads the figure at its rate until the duration ends or a stop signal
// arrives, appending each fresh position to its track.
Sampling sample(LimpFigure& figure, std::vector<Track>& tracks, double duration_s,
                SoundTrackRecorder* microphone, Hold& hold) {
  const RobotConfig& config = figure.config();
  const long period_ns = static_cast<long>(1e9 / config.rate_hz);
  const std::size_t cycles = duration_s > 0
                                 ? static_cast<std::size_t>(duration_s * config.rate_hz) + 1
                                 : std::numeric_limits<std::size_t>::max();
  Sampling run;
  std::vector<double> positions;
  std::vector<bool> fresh;
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  const timespec start = next;
  run.start = start;
  if (microphone) microphone->start();
  RunControls& controls = commissioning_controls();
  for (std::size_t cycle = 0; cycle < cycles && !controls.stop.load(); ++cycle) {
    timespec asked{};
    clock_gettime(CLOCK_MONOTONIC, &asked);
    figure.read(positions, &fresh);
    timespec answered{};
    clock_gettime(CLOCK_MONOTONIC, &answered);
    if (hold.any) {
      hold.follow(positions, fresh);
      figure.write(hold.goals);
    }
    // A sample's time is the middle of its read, not its deadline: a late
    // read (a busy host) must not shift the motion in time.
    const auto since_start = [&start](const timespec& at) {
      return static_cast<double>(at.tv_sec - start.tv_sec) +
             static_cast<double>(at.tv_nsec - start.tv_nsec) * 1e-9;
    };
    const double t = 0.5 * (since_start(asked) + since_start(answered));
    ++run.reads;
    run.last_t = t;
    // A device that did not answer this time gives no sample: its old
    // value at a new time would be a motion that never happened.
    for (Track& track : tracks) {
      if (!fresh[track.joint]) {
        ++run.missed;
        continue;
      }
      if (!track.times.empty() && t < track.times.back() + kMinSampleGap) continue;
      const double v = positions[track.joint];
      track.times.push_back(t);
      track.values.push_back(track.prismatic ? v : rad_to_deg(v));
    }
    // The duration is time, not a count of reads: reads that ran late (a
    // busy host, silent devices) give fewer samples, never a longer take.
    if (duration_s > 0 && since_start(answered) >= duration_s) break;
    next.tv_nsec += period_ns;
    while (next.tv_nsec >= 1'000'000'000L) {
      next.tv_nsec -= 1'000'000'000L;
      ++next.tv_sec;
    }
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
  }
  return run;
}

// All samples kept; a track with fewer than two cannot make a show.
std::size_t count_samples(const std::vector<Track>& tracks) {
  std::size_t samples = 0;
  for (const Track& t : tracks) {
    if (t.times.size() < 2) {
      throw std::runtime_error(t.name +
                               ": fewer than two answers from its device: no show written");
    }
    samples += t.times.size();
  }
  return samples;
}

// The show's audio line: the sound track's file and its offset from the motion.
std::string finish_audio_line(SoundTrackRecorder& microphone, const timespec& start,
                              const std::string& track_name) {
  const double first_sample = microphone.finish();
  const double offset = first_sample - (static_cast<double>(start.tv_sec) + start.tv_nsec * 1e-9);
  std::string quoted = "\"";
  for (const char c : track_name) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return "audio: {file: " + quoted + "\", offset_s: " + number(offset, 4) + "}\n";
}

struct Reduction {
  std::size_t keys_total = 0;
  std::size_t clamped = 0;
};

// Appends each track to the show text as the keys that stay within the
// tolerance of what was recorded.
Reduction reduce_tracks(std::vector<Track>& tracks, const RobotConfig& config, double tolerance_deg,
                        std::string& text) {
  Reduction reduction;
  for (Track& t : tracks) {
    const JointSpec& spec = config.joints[t.joint];
    const double scale = t.prismatic ? 1.0 : rad_to_deg(1.0);
    const double lo = spec.limits.min_position * scale;
    const double hi = spec.limits.max_position * scale;
    // A hand may push a joint past its limits; a show may not go there.
    for (double& v : t.values) {
      if (v < lo || v > hi) ++reduction.clamped;
      v = std::clamp(v, lo, hi);
    }
    const double bound = (t.prismatic ? tolerance_deg / 1000.0 : tolerance_deg);
    const double margin = kValueQuantum * (t.prismatic ? 1e-3 : 1.0);
    const std::vector<std::size_t> keys =
        show::reduce_keys(t.times, t.values, std::max(0.0, bound - margin));
    reduction.keys_total += keys.size();
    text += "  " + t.name + ":\n    interpolation: linear\n";
    if (t.prismatic) text += "    unit: m\n";
    text += "    keys:\n";
    for (const std::size_t k : keys) {
      // Rounding must not carry a key at a limit past it.
      double v = std::round(t.values[k] / margin) * margin;
      v = std::clamp(v, lo, hi);
      text += "      - [" + number(t.times[k], 4) + ", " + number(v, t.prismatic ? 6 : 3) + "]\n";
    }
  }
  return reduction;
}

void write_show(const std::string& out_file, const std::string& text) {
  {
    std::ofstream out(out_file, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) throw std::runtime_error("cannot write " + quote_path(out_file));
  }
  load_show_file(out_file);  // what was written reads back as a show
}

// --compliant: each recorded joint whose servo has current or torque control
// held by that share of its current limit (or full torque), the others limp
// (and named).
Hold hold_compliant(LimpFigure& figure, const std::vector<Track>& tracks, double percent) {
  Hold hold;
  hold.goals.assign(figure.config().joints.size(), std::nan(""));
  if (percent <= 0.0) return hold;
  std::vector<double> positions;
  std::vector<std::string> limp;
  for (const Track& t : tracks) {
    // Held where it is, as its servo says (never a lost answer's old value).
    figure.read_fresh(t.joint, positions);
    if (figure.hold_weakly(t.joint, percent / 100.0)) {
      hold.goals[t.joint] = positions[t.joint];
      hold.any = true;
    } else {
      limp.push_back(t.name);
    }
  }
  if (!limp.empty()) {
    std::cout << "limp (their servos have no current or torque control): "
              << fmt::format("{}", fmt::join(limp, ", ")) << '\n';
  }
  return hold;
}

int run_record(const RecordArgs& args) {
  install_stop_signals(commissioning_controls(), SecondSignal::end_process);
  check_writable(args.out);
  // The microphone is opened before the figure: a missing one is found
  // before anyone starts to puppeteer.
  const std::filesystem::path out_path(args.out);
  const std::string track_name = out_path.stem().string() + ".wav";
  std::unique_ptr<SoundTrackRecorder> microphone;
  if (args.audio) {
    microphone = std::make_unique<SoundTrackRecorder>(
        args.audio_device, kSoundTrackRate, (out_path.parent_path() / track_name).string());
  }
  LimpFigure figure(args.robot, args.ports);
  const RobotConfig& config = figure.config();
  std::vector<Track> tracks = choose_tracks(args, figure);
  Hold hold = hold_compliant(figure, tracks, args.compliant_percent);
  std::cout << (hold.any ? "held by a weak torque" : "torque is off")
            << ": move the figure; recording at " << config.rate_hz << " Hz "
            << (args.duration_s > 0 ? fmt::format("for {} s", args.duration_s)
                                    : std::string("until Ctrl-C"))
            << std::endl;

  const Sampling run = sample(figure, tracks, args.duration_s, microphone.get(), hold);
  figure.let_go();
  const std::size_t samples = count_samples(tracks);

  const std::string audio_line =
      microphone ? finish_audio_line(*microphone, run.start, track_name) : std::string();
  std::string text = fmt::format(
      "# Recorded by hand with animrt record from {}: {} reads at {} Hz, reduced to keys\n"
      "# within {} deg ({} m for prismatic joints) under linear interpolation.\n"
      "name: {}\nloop: false\nduration_s: {}\n{}joints:\n",
      std::filesystem::path(config.file).filename().string(), run.reads, config.rate_hz,
      args.tolerance_deg, args.tolerance_deg / 1000.0, out_path.stem().string(),
      number(run.last_t, 4), audio_line);
  const Reduction reduction = reduce_tracks(tracks, config, args.tolerance_deg, text);
  write_show(args.out, text);
  std::cout << fmt::format(
      "{}: {} joints, {} samples over {:.2f} s -> {} keys (reduction {:.1f}:1 at {} deg)\n",
      args.out, tracks.size(), samples, run.last_t, reduction.keys_total,
      reduction.keys_total > 0
          ? static_cast<double>(samples) / static_cast<double>(reduction.keys_total)
          : 0.0,
      args.tolerance_deg);
  if (run.missed > 0) {
    std::cout << run.missed << " answers were missing (those samples were left out)\n";
  }
  if (reduction.clamped > 0) {
    std::cout << reduction.clamped
              << " samples were past the joints' limits and were clamped to them\n";
  }
  return kExitOk;
}

}  // namespace record_cmd

void add_record_command(CLI::App& app) {
  using namespace record_cmd;
  static RecordArgs args;
  auto* cmd = app.add_subcommand(
      "record", "Puppeteering: torque off, record the figure moved by hand as a show");
  cmd->add_option("ROBOT", args.robot, "robot file (YAML)")->required();
  cmd->add_option("--out", args.out, "the show file to write (YAML)")->required();
  cmd->add_option("--tolerance-deg", args.tolerance_deg,
                  "how far the keys may stray from what was recorded (deg; prismatic joints: "
                  "this many mm)")
      ->check(FiniteRange(0.0, 45.0));
  cmd->add_option("--duration", args.duration_s, "seconds to record (0: until Ctrl-C)")
      ->check(FiniteRange(0.0, 24.0 * 3600.0));
  cmd->add_option("--joint", args.joints, "record only this joint (repeatable)");
  cmd->add_flag("--audio", args.audio,
                "record the microphone beside the motion as the show's sound track (SHOW.wav)");
  cmd->add_option("--audio-device", args.audio_device,
                  "the capture for --audio: an ALSA device or pipe:PATH (default: default)");
  cmd->add_option_function<std::string>(
      "--sound",
      [](const std::string& capture) {
        args.audio = true;
        args.audio_device = capture;
      },
      "CAPTURE: record the sound track from this capture (an ALSA device, or pipe:PATH: "
      "s16le mono at 48 kHz from a FIFO, as a head's capture key) into SHOW.wav");
  cmd->add_option(
         "--compliant", args.compliant_percent,
         "PERCENT: hold the figure by a weak torque, this share of each servo's current "
         "limit (Dynamixel current-based position mode; Feetech STS: its Torque Limit), so "
         "it does not sag while it is moved; the others stay limp (default 0: all limp)")
      ->check(FiniteRange(0.0, 50.0));
  args.ports.add_option(cmd);
  set_subcommand_body(cmd, [] {
    try {
      return run_record(args);
    } catch (const DeviceError& e) {
      std::cerr << "error: " << e.what() << '\n';
      return kExitDeviceError;
    }
  });
}

}  // namespace animrt::cli
