#pragma once
// A pseudo-terminal for a simulated serial device: the device side keeps the
// master (non-blocking), the client opens `path`. The slave stays open here
// so the master never sees a hangup between clients. Raw 8N1.

#include <string>

namespace animrt::sim {

class PtyPair {
 public:
  // Throws DeviceError naming `owner` when no pty can be opened.
  explicit PtyPair(const std::string& owner);
  ~PtyPair();
  PtyPair(const PtyPair&) = delete;
  PtyPair& operator=(const PtyPair&) = delete;

  int master() const { return master_; }
  const std::string& path() const { return path_; }

 private:
  int master_ = -1;
  int slave_ = -1;
  std::string path_;
};

// A pipe to wake a serving thread out of poll().
class WakePipe {
 public:
  WakePipe();
  ~WakePipe();
  WakePipe(const WakePipe&) = delete;
  WakePipe& operator=(const WakePipe&) = delete;
  int read_fd() const { return fds_[0]; }
  void wake();
  void drain();

 private:
  int fds_[2] = {-1, -1};
};

}  // namespace animrt::sim
