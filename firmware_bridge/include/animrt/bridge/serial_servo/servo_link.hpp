#pragma once
// The serial-servo bus core: what every half-duplex servo bus of the kind
// "one instruction packet out, status packets back" shares, whatever its
// family (Dynamixel Protocol 2.0, Feetech SCS/STS; Herkulex or LX-16A would
// be the same). A bus of a family owns one Link and adds only what its
// servos need beyond positions (limits in EEPROM, a bus watchdog, ...).
//
// The core does, once for every family:
// - framing: pulls bytes from the transport through the family's streaming
//   decoder, which resynchronises on the next header after junk, a bad
//   length or a bad checksum;
// - transactions: sends one instruction and collects the answers of the
//   devices asked (one for a unicast, several in order for a Sync Read),
//   telling answers from the adapter's echo, late answers of earlier
//   requests, answers of the wrong length and junk;
// - one timeout semantics: BusConfig::timeout_s is the wait for ONE answer,
//   from the instruction to the first answer and from each answer to the
//   next, so N healthy servos never time out a read because N answers take
//   longer than one; a silent servo costs one timeout (a lifecycle step's
//   retries wait two, then four: unicast; a ping's do not, its rounds are
//   its patience, nor a stop's: Stopping). Past the wait the
//   core looks once more without waiting: an answer queued while this
//   thread was not running is not a timeout. On a lockstep line to
//   simulated devices (lockstep_line.hpp) an answer is missing once the
//   devices have settled without it, whatever the wall clock says;
// - the status book (StatusBook): every counter and health change;
// - ping rounds at configure (ping_until_answered) and the one error that
//   lists every device that stayed silent or answered garbage.
//
// What a new family supplies:
// 1. A codec (packet layout, checksum or CRC, instruction numbers; its
//    encoders and streaming decoder are its own, checked against the
//    vendor's example packets), wrapped in a small struct with:
//      using Packet; using Decoder;            // Decoder: feed/next/reset/buffered
//      static constexpr std::size_t kMaxPacket;
//      static constexpr bool kFaultInErrorByte; // the error byte IS the fault
//                                               // register (else read it: take_new_fault())
//      Frame next(Decoder&, Packet&) const;     // the decoder's verdict
//      bool from_device(const Packet&, std::span<const std::uint8_t> sent) const;
//                                               // false: our own echo, a broadcast
//      std::uint8_t id(const Packet&) const;
//      bool split(const Packet&, std::uint8_t& error,
//                 std::span<const std::uint8_t>& data) const;  // false: no error byte
//      bool rejects(std::uint8_t error) const;  // the error byte refuses the instruction
//      bool fault(std::uint8_t error) const;    // the error byte reports a device fault
//      std::uint32_t value(std::span<const std::uint8_t> data) const;  // byte order
// 2. A model table: control-table addresses and ranges per model (present
//    and goal position, torque enable, position limits, their sizes).
// 3. A thin bus class: it builds the codec's instructions into tx() and
//    calls transact() / unicast() / ping_all(), keeps its positions in a
//    ServoPositions (servo_positions.hpp), and adds the lifecycle steps its
//    servos need (limits in EEPROM, a bus watchdog). The simulated side
//    shares the same codec adapter (sim/serial_line.hpp).

#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/status_book.hpp"

namespace animrt::servo {

// Any data length is fine (a ping's answer, say).
inline constexpr std::size_t kAnyLength = std::numeric_limits<std::size_t>::max();

// What became of one device's answer in a transaction.
enum class Answer : std::uint8_t {
  pending,
  ok,        // status packet with usable data (value() holds it)
  rejected,  // status packet that refuses the instruction, or with the wrong data length
  timeout,   // nothing arrived
  garbled,   // bad checksum, or junk / truncated / wrong-id packet and nothing better
};

// A codec decoder's verdict on what it has buffered.
enum class Frame : std::uint8_t { packet, need_more, bad_check, malformed };

// Throws DeviceError ("bus NAME: device id 3 (knee) ...") for an id outside
// 0..max_id, an id used twice, a direction other than +-1, a scale that is
// not positive, or more than max_devices devices.
void check_bindings(const BusConfig& config, int max_id, std::size_t max_devices);

// "0x2C".
std::string hex_byte(std::uint8_t v);
// A fault register for messages: "`what` 0x24: overheating, overload",
// naming each set bit found in `names`.
struct FaultBit {
  std::uint8_t bit;
  const char* name;
};
std::string fault_text(const char* what, std::uint8_t bits, std::span<const FaultBit> names);

// After configure()'s ping rounds: throws the DeviceError that names every
// device that never answered (`answered` false; `garbled` true when what
// came was garbage), or the line's failure.
void throw_unanswered(const StatusBook& book, const ByteTransport& transport,
                      const std::vector<bool>& answered, const std::vector<bool>& garbled);

// The wait for the answers of one transaction (see the top): one timeout
// for the first answer, each answer starts the next; never longer than one
// timeout per answer expected.
class AnswerClock {
 public:
  using Clock = std::chrono::steady_clock;
  AnswerClock(std::chrono::microseconds timeout, std::size_t answers)
      : timeout_(timeout),
        cap_(Clock::now() + timeout * static_cast<std::int64_t>(std::max<std::size_t>(answers, 1))),
        deadline_(std::min(cap_, Clock::now() + timeout)) {}
  void answered() { deadline_ = std::min(cap_, Clock::now() + timeout_); }
  Clock::time_point deadline() const { return deadline_; }

 private:
  std::chrono::microseconds timeout_;
  Clock::time_point cap_;
  Clock::time_point deadline_;
};

template <class Codec>
class Link {
 public:
  using Packet = typename Codec::Packet;
  using Clock = std::chrono::steady_clock;

  // Takes the open transport; allocates every buffer the cycle needs.
  // Throws DeviceError for a missing transport or a timeout that is not
  // positive (bindings: check_bindings).
  Link(const BusConfig& config, std::unique_ptr<ByteTransport> transport, Codec codec)
      : codec_(codec), transport_(std::move(transport)) {
    const std::string bus = "bus " + config.name + ": ";
    if (!transport_) throw DeviceError(bus + "no transport");
    if (!(config.timeout_s > 0.0)) throw DeviceError(bus + "timeout must be positive");
    timeout_ = std::chrono::ceil<std::chrono::microseconds>(
        std::chrono::duration<double>(config.timeout_s));
    transport_->set_timeout(timeout_);
    book_ = StatusBook(config, transport_->port());
    const std::size_t n = config.actuators.size();
    device_of_id_.fill(-1);
    for (std::size_t i = 0; i < n; ++i) {
      const int id = config.actuators[i].device_id;
      if (id >= 0 && id < 256)
        device_of_id_[static_cast<std::size_t>(id)] = static_cast<std::int16_t>(i);
      bus_ids_.push_back(static_cast<std::uint8_t>(id));
    }
    ids_.resize(n);
    asked_.resize(n);
    answer_.resize(n);
    suspect_.resize(n);
    value_.resize(n);
    data_.resize(n);
    data_size_.resize(n);
    fault_seen_.resize(n);
    fault_new_.resize(n);
  }

  const Codec& codec() const { return codec_; }
  Codec& codec() { return codec_; }
  ByteTransport& transport() { return *transport_; }
  StatusBook& book() { return book_; }
  const StatusBook& book() const { return book_; }
  std::chrono::microseconds timeout() const { return timeout_; }
  std::uint8_t bus_id(std::size_t device) const { return bus_ids_[device]; }

  // Where instructions are built.
  std::span<std::uint8_t> tx() { return tx_; }

  // Counters back to zero (configure()).
  void reset() {
    book_.reset();
    std::fill(fault_seen_.begin(), fault_seen_.end(), 0);
    std::fill(fault_new_.begin(), fault_new_.end(), 0);
  }

  // Per slot of the current transaction: the bus id, the device asked, what
  // came of it and its value.
  std::span<std::uint8_t> ids() { return ids_; }
  std::size_t asked(std::size_t slot) const { return asked_[slot]; }
  Answer answer(std::size_t slot) const { return answer_[slot]; }
  std::uint32_t value(std::size_t slot) const { return value_[slot]; }
  // The answer's data bytes (the first kSlotBytes), for reads of several
  // registers at once.
  static constexpr std::size_t kSlotBytes = 16;
  std::span<const std::uint8_t> data(std::size_t slot) const {
    return {data_[slot].data(), data_size_[slot]};
  }
  // Slots 0..count for every device not faulted; returns count.
  std::size_t ask_all_healthy() {
    std::size_t count = 0;
    for (std::size_t i = 0; i < book_.size(); ++i) {
      if (book_.faulted(i)) continue;
      ids_[count] = bus_ids_[i];
      asked_[count] = i;
      ++count;
    }
    return count;
  }
  // Slot `slot` asks `device`.
  void ask(std::size_t slot, std::size_t device) {
    ids_[slot] = bus_ids_[device];
    asked_[slot] = device;
  }
  void swap_slots(std::size_t a, std::size_t b) {
    std::swap(ids_[a], ids_[b]);
    std::swap(asked_[a], asked_[b]);
    std::swap(answer_[a], answer_[b]);
    std::swap(value_[a], value_[b]);
    std::swap(data_[a], data_[b]);
    std::swap(data_size_[a], data_size_[b]);
    std::swap(suspect_[a], suspect_[b]);
  }

  // A fault appeared on the device since the last call (its alert or fault
  // bits were clear before): a family whose error byte is no fault register
  // reads the register then, once per episode.
  bool take_new_fault(std::size_t device) {
    const bool was = fault_new_[device] != 0;
    fault_new_[device] = 0;
    return was;
  }
  bool fault_pending() const {
    return std::any_of(fault_new_.begin(), fault_new_.end(), [](std::uint8_t f) { return f != 0; });
  }

  // Sends tx()[0, length) without waiting for anything (a write, a broadcast).
  void send(std::size_t length) {
    sent_length_ = length;
    transport_->write({tx_.data(), length});
    last_sent_ = Clock::now();
  }
  Clock::time_point last_sent() const { return last_sent_; }

  // Sends tx()[0, length) and collects the answers of slots [0, count)
  // (data_length bytes each, or kAnyLength) until each answered or the wait
  // for the next answer ran out. `diagnostic`: a read for a diagnosis, whose
  // fault bits are not counted again. `wait`: the wait for one answer, the
  // bus's timeout unless given. Never throws or allocates.
  void transact(std::size_t length, std::size_t count, std::size_t data_length,
                bool diagnostic = false, std::chrono::microseconds wait = {}) {
    begin(length, count);
    AnswerClock clock(wait.count() > 0 ? wait : timeout_, count);
    std::size_t remaining = count;
    std::size_t expected = 0;  // first slot still waiting: whose answer comes next
    Packet packet;
    while (remaining > 0) {
      while (answer_[expected] != Answer::pending) ++expected;
      const Frame r = next_event(packet, clock.deadline());
      if (r == Frame::need_more) break;
      if (r == Frame::bad_check) {
        // A whole packet arrived damaged: that was the answer, no other follows.
        blame(expected, true);
        --remaining;
        clock.answered();
        continue;
      }
      std::size_t slot = count;
      if (r == Frame::packet) {
        // Our own instruction echoed by a half-duplex adapter is no answer.
        if (!codec_.from_device(packet, {tx_.data(), sent_length_})) continue;
        slot = expected;
        while (slot < count &&
               !(ids_[slot] == codec_.id(packet) && answer_[slot] == Answer::pending)) {
          ++slot;
        }
      }
      if (slot < count && stale(packet, data_length)) {
        // Right id, but no answer to this instruction (a late answer to an
        // earlier one): the real answer may still come.
        suspect(slot);
        continue;
      }
      if (slot == count && r == Frame::packet && device_of_id_[codec_.id(packet)] >= 0) {
        // A late answer of another device on this bus: its own fault, not
        // the fault of the device whose answer is awaited.
        book_.stray(static_cast<std::size_t>(device_of_id_[codec_.id(packet)]));
        continue;
      }
      if (slot == count) {
        // Junk that looked like a header, or a packet from an id not asked
        // (or answered twice): counted, and the real answer still awaited.
        suspect(expected);
        continue;
      }
      accept(slot, packet, data_length, diagnostic);
      --remaining;
      clock.answered();
    }
    // Bytes of an unfinished packet at the end: the next answer was cut short.
    settle(count, decoder_.buffered() > 0);
  }

  // One device, one instruction in tx()[0, length): up to `tries` attempts
  // while nothing usable came (a verdict, ok or rejected, is not retried).
  // Each retry waits twice as long as the try before it (one timeout, two,
  // four): a host too busy to carry the line's bytes for a few timeouts (a
  // desktop starting a browser) does not fail a lifecycle step, while a
  // silent device costs 7 timeouts in 3 tries. Within a Stopping scope each
  // try waits one timeout. An answer to an earlier try that comes during a
  // later one is taken: it answers the same instruction. The answers to the
  // tries after it may still be on their way: a status packet names no
  // instruction, so one that came during the device's next transaction
  // would pass for its answer (a Present Position taken for the Homing
  // Offset read next). They are read away here, within as long again as
  // the tries took (one timeout within a Stopping scope); the cycle's own
  // transactions are never retried, so never wait for them.
  Answer unicast(std::size_t device, std::size_t length, std::size_t data_length, int tries,
                 bool diagnostic = false) {
    Answer a = Answer::timeout;
    if (length == 0) return a;
    const Clock::time_point first = Clock::now();
    int t = 0;
    for (; t < tries; ++t) {
      ask(0, device);
      const int doubled = stopping_ ? 0 : std::min(t, 10);
      transact(length, 1, data_length, diagnostic, timeout_ * (std::int64_t{1} << doubled));
      a = answer_[0];
      if (a == Answer::ok || a == Answer::rejected) break;
    }
    if (t > 0 && t < tries) {
      const Clock::time_point now = Clock::now();
      read_away(device, t, stopping_ ? now + timeout_ : now + (now - first));
    }
    return a;
  }

  // While one lives, unicast's retries wait one timeout each: stopping
  // (deactivate), a silent device must hold up the torque-off of the
  // devices after it, and of the buses after this one, no longer than it
  // has to.
  class Stopping {
   public:
    explicit Stopping(Link& link) : link_(link), was_(link.stopping_) { link.stopping_ = true; }
    ~Stopping() { link_.stopping_ = was_; }
    Stopping(const Stopping&) = delete;
    Stopping& operator=(const Stopping&) = delete;

   private:
    Link& link_;
    bool was_;
  };

  // configure()'s search for the devices: pings each (kTries attempts, then
  // again for kPingRounds rounds while any is silent: ping_until_answered),
  // with the ping `encode(id, tx())` builds. A device that answered at all
  // (ok or rejected) is there; seen(device) is called after each ok answer
  // (value(0) holds its data). Throws the DeviceError naming every device
  // that stayed silent or answered garbage.
  template <class Encode, class Seen>
  void ping_all(int tries, Encode&& encode, Seen&& seen) {
    const std::size_t n = book_.size();
    std::vector<bool> garbled(n, false);
    const std::vector<bool> answered = ping_until_answered(n, [&](std::size_t i) {
      // Tries of one timeout each: the rounds are a ping's patience.
      const std::size_t length = encode(bus_ids_[i], tx());
      Answer a = Answer::timeout;
      for (int t = 0; t < tries && a != Answer::ok && a != Answer::rejected; ++t) {
        a = unicast(i, length, kAnyLength, 1);
      }
      if (a == Answer::ok) seen(i);
      garbled[i] = a == Answer::garbled;
      return a == Answer::ok || a == Answer::rejected;
    });
    throw_unanswered(book_, *transport_, answered, garbled);
  }

  // For a family's own transaction kinds (a Dynamixel Fast Sync Read):
  // begin() sends and counts, judge() takes one answer's error byte and
  // data, blame()/suspect() count what came instead, settle() turns the
  // slots still pending into timeouts (or, `truncated`, the first into a
  // protocol error).
  void begin(std::size_t length, std::size_t count) {
    for (std::size_t s = 0; s < count; ++s) {
      answer_[s] = Answer::pending;
      suspect_[s] = 0;
      book_.asked(asked_[s]);
    }
    // Late answers from an earlier transaction must not pass for this one's.
    transport_->discard_input();
    decoder_.reset();
    rx_begin_ = rx_end_ = 0;
    late_look_done_ = false;
    send(length);
  }
  void judge(std::size_t slot, std::uint8_t error, std::span<const std::uint8_t> data,
             std::size_t data_length, bool diagnostic) {
    const std::size_t device = asked_[slot];
    DeviceStatus& st = book_[device];
    const bool fault = codec_.fault(error);
    st.last_error_byte = error;
    if (!diagnostic) {
      if (fault) {
        book_.fault_reported(device);
        if constexpr (Codec::kFaultInErrorByte) {
          st.hardware_error_status = error;
        } else if (fault_seen_[device] == 0) {
          fault_new_[device] = 1;  // read the fault register once per episode
        }
      }
      fault_seen_[device] = fault ? 1 : 0;
    }
    const bool refused = codec_.rejects(error);
    if (refused || (data_length != kAnyLength && data.size() != data_length)) {
      book_.rejected(device, fault);
      answer_[slot] = Answer::rejected;
      return;
    }
    value_[slot] = codec_.value(data);
    data_size_[slot] = static_cast<std::uint8_t>(std::min(data.size(), kSlotBytes));
    std::copy_n(data.begin(), data_size_[slot], data_[slot].begin());
    answer_[slot] = Answer::ok;
    book_.answered(device, fault);
  }
  void blame(std::size_t slot, bool checksum) {
    book_.garbled(asked_[slot], checksum);
    answer_[slot] = Answer::garbled;
  }
  void suspect(std::size_t slot) {
    book_.garbled(asked_[slot]);
    suspect_[slot] = 1;
  }
  void settle(std::size_t count, bool truncated) {
    for (std::size_t s = 0; s < count; ++s) {
      if (answer_[s] != Answer::pending) continue;
      answer_[s] = Answer::garbled;
      if (suspect_[s] != 0) continue;  // already counted as a protocol error
      if (truncated) {
        truncated = false;
        book_.garbled(asked_[s]);
        continue;
      }
      book_.timed_out(asked_[s]);
      answer_[s] = Answer::timeout;
    }
  }

  // Reads raw bytes into `buffer` after `got` until `done(bytes so far)` or
  // the clock's deadline (with the one late look); returns the new count.
  template <class Done>
  std::size_t read_raw(std::span<std::uint8_t> buffer, std::size_t got, AnswerClock& clock,
                       Done&& done) {
    bool late = false;
    const bool line = transport_->follows_line();
    for (;;) {
      if (done(std::span<const std::uint8_t>(buffer.data(), got)) || got == buffer.size()) break;
      const auto now = Clock::now();
      std::chrono::microseconds wait{0};
      if (line) {
        wait = timeout_;  // the line, not the wall clock, says when nothing more comes
      } else if (now < clock.deadline()) {
        wait = std::chrono::ceil<std::chrono::microseconds>(clock.deadline() - now);
      } else if (late) {
        break;
      } else {
        late = true;
      }
      const std::size_t n = transport_->read(buffer.subspan(got), wait);
      got += n;
      if (n == 0 && (line || wait.count() == 0 || transport_->failure() != nullptr)) break;
    }
    return got;
  }

 private:
  // Reads up to `answers` status packets of `device` (the answers to a
  // unicast's later tries) until `until`, and drops them.
  void read_away(std::size_t device, int answers, Clock::time_point until) {
    late_look_done_ = false;
    Packet packet;
    const std::uint8_t id = bus_ids_[device];
    while (answers > 0) {
      const Frame r = next_event(packet, until);
      if (r == Frame::need_more) break;
      if (r == Frame::packet && codec_.from_device(packet, {tx_.data(), sent_length_}) &&
          codec_.id(packet) == id) {
        --answers;
      }
    }
    decoder_.reset();
    rx_begin_ = rx_end_ = 0;
  }

  // Pulls bytes until the decoder has something other than need_more, or
  // the deadline passed (and one last look found nothing).
  Frame next_event(Packet& packet, Clock::time_point deadline) {
    for (;;) {
      if (rx_begin_ < rx_end_) {
        rx_begin_ += decoder_.feed({rx_.data() + rx_begin_, rx_end_ - rx_begin_});
      }
      const Frame r = codec_.next(decoder_, packet);
      if (r != Frame::need_more) return r;
      if (rx_begin_ < rx_end_) {
        // Full decoder that still sees no packet: drop its bytes, never stall.
        decoder_.reset();
        continue;
      }
      const auto now = Clock::now();
      std::chrono::microseconds wait{0};
      const bool line = transport_->follows_line();
      if (line) {
        // A lockstep line: a read returns nothing only once the simulated
        // devices have settled without this answer (lockstep_line.hpp).
        wait = timeout_;
      } else if (now < deadline) {
        wait = std::chrono::ceil<std::chrono::microseconds>(deadline - now);
      } else if (late_look_done_) {
        return Frame::need_more;
      } else {
        // Past the deadline, one last look without waiting: an answer
        // already queued while this thread was not running is no timeout.
        late_look_done_ = true;
      }
      rx_begin_ = 0;
      rx_end_ = transport_->read(rx_, wait);
      // A failed line answers nothing, at once: no point waiting.
      if (rx_end_ == 0 && (line || wait.count() == 0 || transport_->failure() != nullptr)) {
        return Frame::need_more;
      }
    }
  }

  // A status packet from the right id that cannot answer this instruction.
  bool stale(const Packet& packet, std::size_t data_length) const {
    std::uint8_t error = 0;
    std::span<const std::uint8_t> data;
    if (data_length == kAnyLength || !codec_.split(packet, error, data)) return false;
    // A refusal is a verdict on this instruction whatever its length.
    if (codec_.rejects(error)) return false;
    return data.size() != data_length;
  }

  void accept(std::size_t slot, const Packet& packet, std::size_t data_length, bool diagnostic) {
    std::uint8_t error = 0;
    std::span<const std::uint8_t> data;
    if (!codec_.split(packet, error, data)) {  // a status packet carries its error byte
      blame(slot, false);
      return;
    }
    judge(slot, error, data, data_length, diagnostic);
  }

  Codec codec_;
  std::unique_ptr<ByteTransport> transport_;
  std::chrono::microseconds timeout_{0};
  StatusBook book_;
  std::array<std::int16_t, 256> device_of_id_{};  // bus id -> device
  std::vector<std::uint8_t> bus_ids_;             // device -> bus id

  std::vector<std::uint8_t> ids_;
  std::vector<std::size_t> asked_;
  std::vector<Answer> answer_;
  std::vector<std::uint8_t> suspect_;  // blamed for junk or a wrong id, still waited for
  std::vector<std::uint32_t> value_;
  std::vector<std::array<std::uint8_t, kSlotBytes>> data_;
  std::vector<std::uint8_t> data_size_;
  std::vector<std::uint8_t> fault_seen_;  // fault bits in the latest status
  std::vector<std::uint8_t> fault_new_;   // a fault appeared: its register is to be read

  std::array<std::uint8_t, Codec::kMaxPacket> tx_{};
  std::size_t sent_length_ = 0;
  Clock::time_point last_sent_{};
  std::array<std::uint8_t, 256> rx_{};
  std::size_t rx_begin_ = 0, rx_end_ = 0;
  bool late_look_done_ = false;
  bool stopping_ = false;  // within a Stopping scope
  typename Codec::Decoder decoder_;
};

}  // namespace animrt::servo
