// OSC 1.0 packets: strings NUL-terminated and padded to four bytes, numbers
// big-endian, a type tag string starting with ',', bundles "#bundle" with a
// time tag and size-prefixed elements.

#include <bit>
#include <cstring>

#include "animrt/runtime/osc_receiver.hpp"

namespace animrt {
namespace {

constexpr int kMaxBundleDepth = 8;

class OscReader {
 public:
  explicit OscReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  bool done() const { return at_ == bytes_.size(); }

  bool string(std::string& out) {
    const std::size_t start = at_;
    std::size_t end = start;
    while (end < bytes_.size() && bytes_[end] != 0) ++end;
    if (end == bytes_.size()) return false;
    const std::size_t padded = (end - start + 4) & ~std::size_t{3};
    if (start + padded > bytes_.size()) return false;
    out.assign(reinterpret_cast<const char*>(bytes_.data() + start), end - start);
    at_ = start + padded;
    return true;
  }
  bool word(std::uint32_t& out) {
    if (bytes_.size() - at_ < 4) return false;
    out = (std::uint32_t{bytes_[at_]} << 24) | (std::uint32_t{bytes_[at_ + 1]} << 16) |
          (std::uint32_t{bytes_[at_ + 2]} << 8) | std::uint32_t{bytes_[at_ + 3]};
    at_ += 4;
    return true;
  }
  bool skip(std::size_t n) {
    if (bytes_.size() - at_ < n) return false;
    at_ += n;
    return true;
  }
  std::span<const std::uint8_t> rest() const { return bytes_.subspan(at_); }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

bool parse_argument(char tag, OscReader& in, OscMessage& message) {
  std::uint32_t w = 0, low = 0;
  std::string text;
  switch (tag) {
    case 'i':
      if (!in.word(w)) return false;
      message.numbers.push_back(static_cast<double>(static_cast<std::int32_t>(w)));
      return true;
    case 'f':
      if (!in.word(w)) return false;
      message.numbers.push_back(static_cast<double>(std::bit_cast<float>(w)));
      return true;
    case 's':
    case 'S':
      return in.string(text);
    case 'b':
      if (!in.word(w) || w > 0x7fffffffu) return false;
      return in.skip((std::size_t{w} + 3) & ~std::size_t{3});
    case 'h':
      if (!in.word(w) || !in.word(low)) return false;
      message.numbers.push_back(
          static_cast<double>(static_cast<std::int64_t>((std::uint64_t{w} << 32) | low)));
      return true;
    case 'd':
      if (!in.word(w) || !in.word(low)) return false;
      message.numbers.push_back(std::bit_cast<double>((std::uint64_t{w} << 32) | low));
      return true;
    case 't':
      return in.skip(8);
    case 'c':
    case 'r':
    case 'm':
      return in.skip(4);
    case 'T':
    case 'F':
      message.numbers.push_back(tag == 'T' ? 1.0 : 0.0);
      return true;
    case 'N':
    case 'I':
      return true;
    default:
      return false;
  }
}

bool parse_message(OscReader& in, std::vector<OscMessage>& out) {
  OscMessage message;
  if (!in.string(message.address) || message.address.empty() || message.address[0] != '/') {
    return false;
  }
  // OSC 1.0 lets old senders leave the type tags out: then no arguments.
  if (!in.done()) {
    std::string tags;
    if (!in.string(tags) || tags.empty() || tags[0] != ',') return false;
    for (std::size_t i = 1; i < tags.size(); ++i) {
      if (!parse_argument(tags[i], in, message)) return false;
    }
    if (!in.done()) return false;
  }
  out.push_back(std::move(message));
  return true;
}

bool parse_element(std::span<const std::uint8_t> bytes, std::vector<OscMessage>& out, int depth) {
  if (bytes.empty() || bytes.size() % 4 != 0) return false;
  OscReader in(bytes);
  if (bytes[0] == '/') return parse_message(in, out);
  std::string head;
  if (depth >= kMaxBundleDepth || !in.string(head) || head != "#bundle" || !in.skip(8)) {
    return false;
  }
  while (!in.done()) {
    std::uint32_t size = 0;
    if (!in.word(size) || size == 0 || size % 4 != 0 || size > in.rest().size()) return false;
    if (!parse_element(in.rest().first(size), out, depth + 1)) return false;
    in.skip(size);
  }
  return true;
}

}  // namespace

bool parse_osc_packet(std::span<const std::uint8_t> packet, std::vector<OscMessage>& out) {
  return parse_element(packet, out, 0);
}

}  // namespace animrt
