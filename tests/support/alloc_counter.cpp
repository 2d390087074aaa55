#include "support/alloc_counter.hpp"

#include <dlfcn.h>
#include <execinfo.h>
#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <thread>
#include <typeinfo>

#include "../../runtime/src/bus_worker.hpp"

// With AddressSanitizer the sanitizer owns malloc: only operator new is
// counted there. Otherwise malloc, calloc, realloc and the aligned forms are
// replaced by counting forwards to glibc's allocator (free stays glibc's
// own; it is the same heap).
#if defined(__SANITIZE_ADDRESS__)
#define ANIMRT_COUNT_MALLOC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ANIMRT_COUNT_MALLOC 0
#endif
#endif
#ifndef ANIMRT_COUNT_MALLOC
#define ANIMRT_COUNT_MALLOC 1
#endif

#if ANIMRT_COUNT_MALLOC
extern "C" {
void* __libc_malloc(std::size_t size) noexcept;
void* __libc_calloc(std::size_t n, std::size_t size) noexcept;
void* __libc_realloc(void* p, std::size_t size) noexcept;
void* __libc_memalign(std::size_t alignment, std::size_t size) noexcept;
void __libc_free(void* p) noexcept;
}
#endif

namespace {

using animrt::test::RunPhase;
using animrt::test::RunThread;

// Role of a thread in the watched run; kNone: not a run thread.
enum Role : int { kLoop, kBusIo, kWriter, kOther, kNone };
constexpr int kRoles = 4;
constexpr int kPhases = 3;

thread_local std::uint64_t allocations = 0;
thread_local Role role = kNone;
thread_local bool in_hook = false;
thread_local bool learning = false;

struct Trace {
  static constexpr int kFrames = 40;
  void* frames[kFrames];
  int depth;
  Role role;
  int phase;
};

struct Watch {
  std::atomic<bool> open{false};
  std::atomic<bool> opened{false};
  std::atomic<int> phase{0};
  std::atomic<std::uint64_t> by_role[kRoles]{};
  std::atomic<std::uint64_t> by_phase[kPhases]{};
  std::atomic<int> started[kRoles]{};
  static constexpr int kTraces = 6;
  std::atomic<int> traces{0};
  Trace trace[kTraces]{};
};
constinit Watch watch;

// The start routine libstdc++ hands pthread_create for every std::thread.
std::atomic<void* (*)(void*)> std_thread_routine{nullptr};

void* raw_malloc(std::size_t size) {
#if ANIMRT_COUNT_MALLOC
  return __libc_malloc(size);
#else
  return std::malloc(size);
#endif
}
void raw_free(void* p) {
#if ANIMRT_COUNT_MALLOC
  __libc_free(p);
#else
  std::free(p);
#endif
}

void note_run_allocation() {
  if (!watch.open.load(std::memory_order_relaxed)) return;
  const Role r = role;
  if (r == kNone || in_hook) return;
  in_hook = true;
  watch.by_role[r].fetch_add(1, std::memory_order_relaxed);
  if (r != kWriter) {
    const int phase = watch.phase.load(std::memory_order_relaxed);
    watch.by_phase[phase].fetch_add(1, std::memory_order_relaxed);
    const int slot = watch.traces.fetch_add(1, std::memory_order_relaxed);
    if (slot < Watch::kTraces) {
      Trace& t = watch.trace[slot];
      t.depth = ::backtrace(t.frames, Trace::kFrames);
      t.role = r;
      t.phase = phase;
    }
  }
  in_hook = false;
}

void* allocate(std::size_t size) {
  ++allocations;
  if (!ANIMRT_COUNT_MALLOC) note_run_allocation();
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}

// --- thread lineage ---------------------------------------------------------

using CreateFn = int (*)(pthread_t*, const pthread_attr_t*, void* (*)(void*), void*);

CreateFn real_pthread_create() {
  static const CreateFn real = reinterpret_cast<CreateFn>(::dlsym(RTLD_NEXT, "pthread_create"));
  return real;
}

struct Start {
  void* (*routine)(void*);
  void* arg;
  Role role;
};

void* start_run_thread(void* p) {
  const Start start = *static_cast<Start*>(p);
  raw_free(p);
  role = start.role;
  return start.routine(start.arg);
}

Role classify(void* (*routine)(void*), void* arg) {
  if (routine != nullptr && routine == animrt::bus_worker_thread_routine()) return kBusIo;
#ifdef __GLIBCXX__
  if (routine != nullptr && routine == std_thread_routine.load()) {
    const char* type = typeid(*static_cast<std::thread::_State*>(arg)).name();
    if (std::strstr(type, "TelemetryWriter") != nullptr) return kWriter;
    if (std::strstr(type, "McapRecorder") != nullptr) return kWriter;
  }
#else
  (void)routine;
  (void)arg;
#endif
  return kOther;
}

// Runs `command` and returns its first line of output.
std::string first_line(const std::string& command) {
  std::string out;
  if (FILE* p = ::popen(command.c_str(), "r")) {
    char buf[512];
    if (std::fgets(buf, sizeof buf, p) != nullptr) out = buf;
    ::pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

// "function at file:line" of a return address, through addr2line.
std::string symbolise(void* address) {
  Dl_info info{};
  char hex[32];
  std::snprintf(hex, sizeof hex, "%p", address);
  if (::dladdr(address, &info) == 0 || info.dli_fname == nullptr) return hex;
  Dl_info self{};
  ::dladdr(reinterpret_cast<void*>(&symbolise), &self);
  std::string file = info.dli_fname;
  if (info.dli_fbase == self.dli_fbase) {  // this executable: its real path, not argv[0]
    char exe[4096];
    const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) file.assign(exe, static_cast<std::size_t>(n));
  }
  char offset[32];
  std::snprintf(offset, sizeof offset, "0x%lx",
                static_cast<unsigned long>(reinterpret_cast<std::uintptr_t>(address) -
                                           reinterpret_cast<std::uintptr_t>(info.dli_fbase) - 1));
  const std::string command = "addr2line -C -f -p -e '" + file + "' " + offset + " 2>/dev/null";
  const std::string line = first_line(command);
  return line.empty() ? std::string(hex) + " in " + file : line;
}

const char* role_name(Role r) {
  switch (r) {
    case kLoop:
      return "loop thread";
    case kBusIo:
      return "bus I/O thread";
    case kWriter:
      return "telemetry writer";
    case kOther:
      return "other run thread";
    case kNone:
      break;
  }
  return "not a run thread";
}

const char* phase_name(int phase) {
  static const char* const names[] = {"start ramp", "motion", "stop ramp"};
  return phase >= 0 && phase < kPhases ? names[phase] : "?";
}

}  // namespace

#if ANIMRT_COUNT_MALLOC
extern "C" {
void* malloc(std::size_t size) noexcept {
  note_run_allocation();
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) noexcept {
  note_run_allocation();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) noexcept {
  note_run_allocation();
  return __libc_realloc(p, size);
}
// The aligned forms (aligned operator new goes through aligned_alloc).
void* memalign(std::size_t alignment, std::size_t size) noexcept {
  note_run_allocation();
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  note_run_allocation();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0) return EINVAL;
  note_run_allocation();
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
}
#endif

// Every thread a run thread starts is a run thread; std::thread is
// recognised by its start routine, learned from one probe thread.
extern "C" int pthread_create(pthread_t* thread, const pthread_attr_t* attr,
                              void* (*routine)(void*), void* arg) {
  const CreateFn real = real_pthread_create();
  if (real == nullptr) return EAGAIN;
  if (learning) std_thread_routine.store(routine);
  if (role == kNone) return real(thread, attr, routine, arg);
  auto* start = static_cast<Start*>(raw_malloc(sizeof(Start)));
  if (start == nullptr) return EAGAIN;
  *start = Start{routine, arg, classify(routine, arg)};
  const Role child = start->role;
  const int rc = real(thread, attr, start_run_thread, start);
  if (rc != 0) {
    raw_free(start);
  } else {
    watch.started[child].fetch_add(1);
  }
  return rc;
}

// Replacements of the global allocation functions (the aligned forms keep
// their defaults, which call aligned_alloc).
void* operator new(std::size_t size) { return allocate(size); }
void* operator new[](std::size_t size) { return allocate(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return allocate(size);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return allocate(size);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace animrt::test {

std::uint64_t thread_allocations() { return allocations; }

RunAllocationWatch::RunAllocationWatch() {
  if (std_thread_routine.load() == nullptr) {
    learning = true;
    std::thread([] {}).join();
    learning = false;
  }
  void* warm_up[4];
  ::backtrace(warm_up, 4);  // loads the unwinder now, not inside the window
  watch.open.store(false);
  watch.opened.store(false);
  watch.phase.store(0);
  for (auto& c : watch.by_role) c.store(0);
  for (auto& c : watch.by_phase) c.store(0);
  for (auto& c : watch.started) c.store(0);
  watch.traces.store(0);
  role = kLoop;
}

RunAllocationWatch::~RunAllocationWatch() {
  close();
  role = kNone;
}

void RunAllocationWatch::open() {
  watch.opened.store(true);
  watch.open.store(true);
}
void RunAllocationWatch::close() { watch.open.store(false); }
void RunAllocationWatch::set_phase(RunPhase phase) { watch.phase.store(static_cast<int>(phase)); }
bool RunAllocationWatch::is_open() const { return watch.open.load(); }
bool RunAllocationWatch::was_opened() const { return watch.opened.load(); }

std::uint64_t RunAllocationWatch::counted() const {
  std::uint64_t n = 0;
  for (int r = 0; r < kRoles; ++r) {
    if (r != kWriter) n += watch.by_role[r].load();
  }
  return n;
}
std::uint64_t RunAllocationWatch::on(RunThread thread) const {
  return watch.by_role[static_cast<int>(thread)].load();
}
std::uint64_t RunAllocationWatch::in(RunPhase phase) const {
  return watch.by_phase[static_cast<int>(phase)].load();
}
int RunAllocationWatch::started(RunThread thread) const {
  return watch.started[static_cast<int>(thread)].load();
}

std::string RunAllocationWatch::where() const {
  const bool was_open = watch.open.exchange(false);  // symbolising allocates
  std::string out;
  const int n = std::min(watch.traces.load(), Watch::kTraces);
  for (int i = 0; i < n; ++i) {
    const Trace& t = watch.trace[i];
    out += std::string("allocation ") + std::to_string(i + 1) + " on the " + role_name(t.role) +
           " during the " + phase_name(t.phase) + ":\n";
    for (int f = 1; f < t.depth; ++f) {
      const std::string frame = symbolise(t.frames[f]);
      if (frame.find("testing::") != std::string::npos) break;  // the test framework below
      out += "    " + frame + "\n";
    }
  }
  watch.open.store(was_open);
  return out;
}

}  // namespace animrt::test
