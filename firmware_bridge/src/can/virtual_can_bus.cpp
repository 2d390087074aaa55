#include "animrt/bridge/can/virtual_can_bus.hpp"

#include <linux/can/error.h>

#include <algorithm>
#include <array>
#include <limits>
#include <map>

#include "animrt/bridge/lockstep_line.hpp"
#include "animrt/core/error.hpp"

namespace animrt {

namespace {
bool passes(const std::vector<can_filter>& filters, const can_frame& frame) {
  for (const can_filter& f : filters) {
    if (((frame.can_id ^ f.can_id) & f.can_mask) == 0) return true;
  }
  return false;
}
}  // namespace

struct VirtualCanBus::Queue {
  std::array<can_frame, kQueueFrames> frames{};
  std::size_t head = 0, size = 0;
  std::vector<can_filter> filters{can_filter{0, 0}};  // everything until set_filters
  std::condition_variable ready;
  CanErrorCounters errors;  // written by the endpoint's thread only
  bool bus_off = false;
  std::uint64_t overflows = 0;  // written under the bus lock
  // A lockstep device's queue (the rest under the bus lock, see the header).
  bool lockstep_device = false;
  bool serving = false;
  std::uint64_t taken = 0;    // frames its receive() returned or consumed
  std::uint64_t handled = 0;  // of those, served
  Nanos polled_at = std::numeric_limits<Nanos>::min();
  bool poke = false;  // its receive() returns at once: poll at the clock's time
};

class VirtualCanEndpoint final : public LockstepCanPort {
 public:
  VirtualCanEndpoint(std::shared_ptr<VirtualCanBus> bus, std::unique_ptr<VirtualCanBus::Queue> q)
      : bus_(std::move(bus)),
        queue_(std::move(q)),
        interface_(std::string(kVirtualCanPrefix) + bus_->name()) {}
  ~VirtualCanEndpoint() override { bus_->detach(queue_.get()); }

  const std::string& interface() const override { return interface_; }

  void set_filters(std::span<const can_filter> filters) override {
    std::lock_guard lock(bus_->mutex_);
    queue_->filters.assign(filters.begin(), filters.end());
  }

  bool send(const can_frame& frame) override {
    if (!bus_->send_from(queue_.get(), frame)) {
      ++queue_->errors.tx_dropped;
      return false;
    }
    return true;
  }

  bool receive(can_frame& frame, std::chrono::microseconds timeout) override {
    VirtualCanBus::Queue& q = *queue_;
    const auto start = std::chrono::steady_clock::now();
    std::unique_lock lock(bus_->mutex_);
    // Following lockstep devices, they say when nothing more will come; the
    // wall clock only guards against a hung device thread.
    const bool follow = !q.lockstep_device && bus_->lockstep_devices_ > 0;
    if (follow) timeout = std::max<std::chrono::microseconds>(timeout, LockstepLine::kGuard);
    const auto deadline = start + timeout;
    for (;;) {
      q.errors.rx_overflows = q.overflows;
      while (q.size > 0) {
        frame = q.frames[q.head];
        q.head = (q.head + 1) % VirtualCanBus::kQueueFrames;
        --q.size;
        if (q.lockstep_device) ++q.taken;
        if ((frame.can_id & CAN_ERR_FLAG) == 0) return true;
        const int change = count_error_frame(frame, q.errors);
        if (change > 0) q.bus_off = true;
        if (change < 0) q.bus_off = false;
      }
      if (q.poke) {
        q.poke = false;
        return false;
      }
      if (follow && bus_->settled_locked()) return false;
      if (q.ready.wait_until(lock, deadline) == std::cv_status::timeout && q.size == 0) {
        return false;
      }
    }
  }

  void serving(bool on) override {
    std::lock_guard lock(bus_->mutex_);
    queue_->serving = on;
    bus_->wake_followers_locked();
  }

  void served(Nanos now) override {
    std::lock_guard lock(bus_->mutex_);
    queue_->handled = queue_->taken;
    queue_->polled_at = std::max(queue_->polled_at, now);
    bus_->wake_followers_locked();
  }

  const CanErrorCounters& errors() const override { return queue_->errors; }
  bool bus_off() const override { return queue_->bus_off; }
  Nanos now() const override { return bus_->now(); }

 private:
  std::shared_ptr<VirtualCanBus> bus_;
  std::unique_ptr<VirtualCanBus::Queue> queue_;
  std::string interface_;
};

std::shared_ptr<VirtualCanBus> VirtualCanBus::named(const std::string& name) {
  static std::mutex registry_mutex;
  static std::map<std::string, std::weak_ptr<VirtualCanBus>> registry;
  std::lock_guard lock(registry_mutex);
  auto& slot = registry[name];
  if (auto bus = slot.lock()) return bus;
  auto bus = std::make_shared<VirtualCanBus>(name);
  slot = bus;
  return bus;
}

VirtualCanBus::VirtualCanBus(std::string name) : name_(std::move(name)) {}

std::unique_ptr<CanFrameTransport> VirtualCanBus::attach() {
  auto queue = std::make_unique<Queue>();
  {
    std::lock_guard lock(mutex_);
    queues_.push_back(queue.get());
  }
  return std::make_unique<VirtualCanEndpoint>(shared_from_this(), std::move(queue));
}

std::unique_ptr<LockstepCanPort> VirtualCanBus::attach_lockstep_device() {
  auto queue = std::make_unique<Queue>();
  queue->lockstep_device = true;
  {
    std::lock_guard lock(mutex_);
    queues_.push_back(queue.get());
    ++lockstep_devices_;
  }
  return std::make_unique<VirtualCanEndpoint>(shared_from_this(), std::move(queue));
}

void VirtualCanBus::detach(Queue* queue) {
  std::lock_guard lock(mutex_);
  queues_.erase(std::remove(queues_.begin(), queues_.end(), queue), queues_.end());
  if (queue->lockstep_device) {
    --lockstep_devices_;
    wake_followers_locked();
  }
}

bool VirtualCanBus::settled_locked() {
  const Nanos now = now_locked();
  bool settled = true;
  for (Queue* q : queues_) {
    if (!q->lockstep_device || !q->serving) continue;
    if (q->size == 0 && q->handled == q->taken && q->polled_at >= now) continue;
    settled = false;
    if (q->size == 0 && !q->poke) {
      q->poke = true;  // idle, but not polled at this time yet
      q->ready.notify_one();
    }
  }
  return settled;
}

void VirtualCanBus::wake_followers_locked() {
  for (Queue* q : queues_) {
    if (!q->lockstep_device) q->ready.notify_all();
  }
}

void VirtualCanBus::set_clock(const Clock* clock) {
  std::lock_guard lock(mutex_);
  clock_ = clock;
}

Nanos VirtualCanBus::now_locked() const {
  if (clock_) return clock_->now();
  return MonotonicClock().now();
}

Nanos VirtualCanBus::now() const {
  std::lock_guard lock(mutex_);
  return now_locked();
}

void VirtualCanBus::deliver_locked(const Queue* sender, const can_frame& frame, bool error) {
  for (Queue* q : queues_) {
    if (q == sender) continue;
    if (!error && !passes(q->filters, frame)) continue;
    if (q->size == kQueueFrames) {
      ++q->overflows;
      continue;
    }
    q->frames[(q->head + q->size) % kQueueFrames] = frame;
    ++q->size;
    q->ready.notify_one();
  }
  ++delivered_;
}

bool VirtualCanBus::send_from(const Queue* sender, const can_frame& frame) {
  std::lock_guard lock(mutex_);
  if (bus_off_) return false;
  if ((frame.can_id & CAN_ERR_FLAG) != 0) return false;  // only controllers make error frames
  deliver_locked(sender, frame, false);
  return true;
}

void VirtualCanBus::inject_error(const can_frame& error_frame) {
  can_frame frame = error_frame;
  frame.can_id |= CAN_ERR_FLAG;
  frame.len = CAN_ERR_DLC;
  std::lock_guard lock(mutex_);
  deliver_locked(nullptr, frame, true);
}

void VirtualCanBus::set_bus_off(bool bus_off) {
  can_frame frame{};
  frame.can_id = CAN_ERR_FLAG | (bus_off ? CAN_ERR_BUSOFF : CAN_ERR_RESTARTED);
  frame.len = CAN_ERR_DLC;
  std::lock_guard lock(mutex_);
  bus_off_ = bus_off;
  deliver_locked(nullptr, frame, true);
}

std::uint64_t VirtualCanBus::frames_delivered() const {
  std::lock_guard lock(mutex_);
  return delivered_;
}

}  // namespace animrt
