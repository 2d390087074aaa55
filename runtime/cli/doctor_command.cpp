#include "doctor_command.hpp"

#include <grp.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/sysinfo.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "subcommand.hpp"

namespace animrt::cli {
// Named, so that the unity build's other commands do not share these names.
namespace doctor_cmd {

namespace fs = std::filesystem;

enum class Status { ok, warn, fail };

struct Check {
  Status status;
  std::string what;  // which check
  std::string detail;
  std::string fix;  // empty when OK
};

// Where /sys and /dev are read from: ANIMRT_DOCTOR_ROOT (a prefix) lets a
// test stand a host of its own making behind the checks.
struct Host {
  fs::path root = "/";
  bool real = true;
  fs::path at(const std::string& absolute) const { return root / absolute.substr(1); }
};

std::string first_line(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
  return line;
}

std::vector<fs::path> entries(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// USB serial adapters by their stable names, and whether this user may open them.
void check_serial(const Host& host, std::vector<Check>& out) {
  const std::vector<fs::path> links = entries(host.at("/dev/serial/by-id"));
  if (links.empty()) {
    out.push_back({Status::warn, "serial adapters", "none in /dev/serial/by-id",
                   "plug the USB adapter in (and check `dmesg` for its driver); a bus on a "
                   "built-in UART needs none"});
    return;
  }
  for (const fs::path& link : links) {
    std::error_code ec;
    fs::path target = fs::canonical(link, ec);
    if (ec) target = link;
    const std::string name = link.filename().string();
    if (::access(target.c_str(), R_OK | W_OK) == 0) {
      out.push_back({Status::ok, "serial adapter", name + " -> " + target.string(), ""});
    } else {
      out.push_back({Status::fail, "serial adapter",
                     name + " -> " + target.string() + ": this user may not open it",
                     "sudo usermod -aG dialout $USER, then log in again"});
    }
  }
}

void check_dialout(std::vector<Check>& out) {
  const group* dialout = ::getgrnam("dialout");
  if (::geteuid() == 0) {
    out.push_back({Status::ok, "dialout", "running as root: every port opens", ""});
    return;
  }
  if (dialout == nullptr) {
    out.push_back({Status::warn, "dialout", "this system has no dialout group",
                   "give this user access to the serial ports by a udev rule"});
    return;
  }
  std::vector<gid_t> groups(static_cast<std::size_t>(std::max(::getgroups(0, nullptr), 0)) + 1);
  const int n = ::getgroups(static_cast<int>(groups.size()), groups.data());
  groups.resize(static_cast<std::size_t>(std::max(n, 0)));
  const bool member = ::getegid() == dialout->gr_gid ||
                      std::find(groups.begin(), groups.end(), dialout->gr_gid) != groups.end();
  if (member) {
    out.push_back({Status::ok, "dialout", "this user is in the dialout group", ""});
  } else {
    out.push_back({Status::warn, "dialout", "this user is not in the dialout group",
                   "sudo usermod -aG dialout $USER, then log in again"});
  }
}

// An FTDI adapter holds received bytes up to its latency timer (16 ms by
// default) before it sends them: a whole loop period lost per answer.
void check_latency(const Host& host, std::vector<Check>& out) {
  bool any = false;
  for (const fs::path& dev : entries(host.at("/sys/bus/usb-serial/devices"))) {
    const fs::path timer = dev / "latency_timer";
    if (!fs::exists(timer)) continue;
    any = true;
    const std::string name = dev.filename().string();
    const std::string value = first_line(timer);
    const int ms = std::atoi(value.c_str());
    if (ms <= 1 && !value.empty()) {
      out.push_back({Status::ok, "latency timer", name + ": " + value + " ms", ""});
    } else {
      out.push_back({Status::warn, "latency timer",
                     name + ": " + value + " ms (every answer waits up to this long)",
                     "echo 1 | sudo tee /sys/bus/usb-serial/devices/" + name +
                         "/latency_timer; to keep it, a udev rule: ACTION==\"add\", "
                         "SUBSYSTEM==\"usb-serial\", DRIVER==\"ftdi_sio\", "
                         "ATTR{latency_timer}=\"1\""});
    }
  }
  if (!any) out.push_back({Status::ok, "latency timer", "no FTDI adapter to tune", ""});
}

void check_limits(std::vector<Check>& out) {
  const bool root = ::geteuid() == 0;
  rlimit rt{};
  ::getrlimit(RLIMIT_RTPRIO, &rt);
  const std::string rtprio =
      rt.rlim_cur == RLIM_INFINITY ? "unlimited" : std::to_string(rt.rlim_cur);
  // What this process got, as a service's LimitRTPRIO= sets it.
  if (root || rt.rlim_cur == RLIM_INFINITY || rt.rlim_cur >= 80) {
    out.push_back({Status::ok, "rtprio limit",
                   "rtprio " + rtprio + (root ? " (root: any priority)" : ""), ""});
  } else {
    out.push_back({Status::warn, "rtprio limit",
                   "rtprio " + std::to_string(rt.rlim_cur) + " (the loop asks for 80)",
                   "the animrt package's /etc/security/limits.d/animrt.conf gives group animrt "
                   "rtprio 95: sudo usermod -aG animrt $USER, then log in again; under "
                   "systemd, LimitRTPRIO=95"});
  }
  rlimit mem{};
  ::getrlimit(RLIMIT_MEMLOCK, &mem);
  const std::string memlock = mem.rlim_cur == RLIM_INFINITY
                                  ? std::string("unlimited")
                                  : std::to_string(mem.rlim_cur / 1024) + " KiB";
  if (root || mem.rlim_cur == RLIM_INFINITY) {
    out.push_back({Status::ok, "memlock limit",
                   "memlock " + memlock + (root ? " (root: no limit)" : ""), ""});
  } else {
    out.push_back({Status::warn, "memlock limit",
                   "memlock " + std::to_string(mem.rlim_cur / 1024) + " KiB",
                   "the animrt package's limits.d file gives group animrt memlock unlimited: "
                   "sudo usermod -aG animrt $USER, then log in again; under systemd, "
                   "LimitMEMLOCK=infinity"});
  }
}

// Whether the requests the loop makes work, tried on a thread of their own.
void check_realtime(std::vector<Check>& out) {
  int error = 0;
  std::thread probe([&error] {
    sched_param param{};
    param.sched_priority = 80;
    error = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param);
  });
  probe.join();
  if (error == 0) {
    out.push_back({Status::ok, "SCHED_FIFO", "priority 80 granted", ""});
  } else {
    out.push_back({Status::warn, "SCHED_FIFO",
                   std::string("refused: ") + std::strerror(error) +
                       " (the loop runs at normal priority and its jitter grows with load)",
                   "raise the rtprio limit (above); in a container, run with --cap-add "
                   "SYS_NICE; under systemd, LimitRTPRIO=95"});
  }
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    ::munlockall();
    out.push_back({Status::ok, "mlockall", "memory can be locked", ""});
  } else {
    out.push_back(
        {Status::warn, "mlockall",
         std::string("refused: ") + std::strerror(errno) + " (a page fault can stall the loop)",
         "raise the memlock limit (above); under systemd, LimitMEMLOCK=infinity"});
  }
}

void check_kernel(const Host& host, std::vector<Check>& out) {
  std::string version = first_line(host.at("/proc/sys/kernel/version"));
  if (host.real) {
    utsname u{};
    if (::uname(&u) == 0) version = u.version;
  }
  const bool rt = first_line(host.at("/sys/kernel/realtime")) == "1" ||
                  version.find("PREEMPT_RT") != std::string::npos;
  if (rt) {
    out.push_back({Status::ok, "kernel", "PREEMPT_RT", ""});
  } else {
    out.push_back({Status::warn, "kernel",
                   "not PREEMPT_RT (" + (version.empty() ? std::string("unknown") : version) +
                       "): worst-case latency is milliseconds under load",
                   "install a real-time kernel (Debian: linux-image-rt-amd64 or "
                   "linux-image-rt-arm64) and boot it"});
  }
}

// "0-3,6": the CPUs of a set as the kernel writes lists (isolcpus, taskset).
std::string cpu_list(const cpu_set_t& set) {
  std::string list;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (!CPU_ISSET(cpu, &set)) continue;
    int last = cpu;
    while (last + 1 < CPU_SETSIZE && CPU_ISSET(last + 1, &set)) ++last;
    list += (list.empty() ? "" : ",") + std::to_string(cpu);
    if (last > cpu) list += "-" + std::to_string(last);
    cpu = last;
  }
  return list;
}

// "1,3-4" back into a set (what /sys/devices/system/cpu/isolated holds).
cpu_set_t parse_cpu_list(const std::string& text) {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, end - at);
    const std::size_t dash = item.find('-');
    const int first = std::atoi(item.c_str());
    const int last = dash == std::string::npos ? first : std::atoi(item.c_str() + dash + 1);
    for (int cpu = std::max(first, 0); cpu <= last && cpu < CPU_SETSIZE; ++cpu) CPU_SET(cpu, &set);
    at = end + 1;
  }
  return set;
}

// Which CPU the process runs on and may run on (the loop's threads inherit
// it), against the CPUs the kernel keeps free of other work (isolcpus=).
void check_cpu(const Host& host, std::vector<Check>& out) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  ::sched_getaffinity(0, sizeof allowed, &allowed);
  const std::string isolated_text = first_line(host.at("/sys/devices/system/cpu/isolated"));
  const cpu_set_t isolated = parse_cpu_list(isolated_text);
  cpu_set_t outside;
  CPU_ZERO(&outside);
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed) && !CPU_ISSET(cpu, &isolated)) CPU_SET(cpu, &outside);
  }
  const std::string detail = "runs on CPU " + std::to_string(::sched_getcpu()) + ", may run on " +
                             cpu_list(allowed) + " of " + std::to_string(::get_nprocs_conf());
  if (CPU_COUNT(&isolated) == 0) {
    out.push_back({Status::ok, "CPU",
                   detail + "; no CPU isolated (isolcpus=) for the loop, which shares them", ""});
  } else if (CPU_COUNT(&outside) == 0) {
    out.push_back({Status::ok, "CPU", detail + ", isolated " + cpu_list(isolated), ""});
  } else {
    const std::string pin = cpu_list(isolated);
    out.push_back({Status::warn, "CPU",
                   detail + ": isolated " + pin + " but the loop may run outside it",
                   "pin it there: under systemd, CPUAffinity=" + pin +
                       " (systemctl edit animrt); "
                       "from a shell, taskset -c " +
                       pin + " animrt ..."});
  }
}

void check_governor(const Host& host, std::vector<Check>& out) {
  std::vector<std::string> slow;
  int cpus = 0;
  for (const fs::path& cpu : entries(host.at("/sys/devices/system/cpu"))) {
    const fs::path file = cpu / "cpufreq" / "scaling_governor";
    if (!fs::exists(file)) continue;
    ++cpus;
    const std::string governor = first_line(file);
    if (governor != "performance") slow.push_back(cpu.filename().string() + " " + governor);
  }
  if (cpus == 0) {
    out.push_back({Status::ok, "CPU governor", "no frequency scaling (fixed clock)", ""});
  } else if (slow.empty()) {
    out.push_back({Status::ok, "CPU governor", "performance on every CPU", ""});
  } else {
    std::string list;
    for (const std::string& s : slow) list += (list.empty() ? "" : ", ") + s;
    out.push_back({Status::warn, "CPU governor",
                   list + " (a clock that slows down delays the cycle)",
                   "sudo cpupower frequency-set -g performance"});
  }
}

// The bitrate lives in netlink, not sysfs: `ip -details` says it.
std::string can_bitrate(const std::string& name) {
  if (name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-") !=
      std::string::npos) {
    return "";
  }
  FILE* pipe = ::popen(("ip -details link show dev " + name + " 2>/dev/null").c_str(), "r");
  if (pipe == nullptr) return "";
  std::string text;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) text += buffer;
  ::pclose(pipe);
  const std::size_t at = text.find("bitrate ");
  if (at == std::string::npos) return "";
  return text.substr(at + 8, text.find_first_of(" \n", at + 8) - (at + 8));
}

void check_can(const Host& host, std::vector<Check>& out) {
  bool any = false;
  for (const fs::path& net : entries(host.at("/sys/class/net"))) {
    if (first_line(net / "type") != "280") continue;  // ARPHRD_CAN
    any = true;
    const std::string name = net.filename().string();
    const unsigned long flags = std::strtoul(first_line(net / "flags").c_str(), nullptr, 16);
    const bool up = (flags & 0x1) != 0;  // IFF_UP
    const std::string bitrate = host.real ? can_bitrate(name) : first_line(net / "bitrate");
    const std::string rate = bitrate.empty() ? "" : ", bitrate " + bitrate;
    if (up) {
      out.push_back({Status::ok, "CAN", name + " up" + rate, ""});
    } else {
      out.push_back({Status::fail, "CAN", name + " is down" + rate,
                     "sudo ip link set " + name +
                         " up type can bitrate 1000000 (the bitrate "
                         "your drives use; a vcan needs only 'ip link set " +
                         name + " up')"});
    }
  }
  if (!any) {
    out.push_back({Status::ok, "CAN", "no CAN interfaces (needed only for CAN buses)", ""});
  }
}

int run_doctor() {
  Host host;
  if (const char* root = std::getenv("ANIMRT_DOCTOR_ROOT"); root != nullptr && *root != '\0') {
    host.root = root;
    host.real = false;
    std::cout << "host files read under " << host.root.string() << " (ANIMRT_DOCTOR_ROOT)\n";
  }
  std::vector<Check> checks;
  check_serial(host, checks);
  check_latency(host, checks);
  check_dialout(checks);
  check_limits(checks);
  check_realtime(checks);
  check_kernel(host, checks);
  check_cpu(host, checks);
  check_governor(host, checks);
  check_can(host, checks);
  int fails = 0;
  int warnings = 0;
  for (const Check& c : checks) {
    const char* tag = c.status == Status::ok ? "OK  " : c.status == Status::warn ? "WARN" : "FAIL";
    std::cout << tag << "  " << c.what << ": " << c.detail;
    if (!c.fix.empty()) std::cout << "\n      fix: " << c.fix;
    std::cout << '\n';
    fails += c.status == Status::fail;
    warnings += c.status == Status::warn;
  }
  std::cout << checks.size() << " checks: " << fails << " failed, " << warnings << " warnings\n";
  return fails > 0 ? kExitDeviceError : kExitOk;
}

}  // namespace doctor_cmd

void add_doctor_command(CLI::App& app) {
  using namespace doctor_cmd;
  auto* cmd = app.add_subcommand(
      "doctor",
      "Check this host for a figure: adapters, latency, permissions, real time, CPUs, CAN");
  set_subcommand_body(cmd, [] { return run_doctor(); });
}

}  // namespace animrt::cli
