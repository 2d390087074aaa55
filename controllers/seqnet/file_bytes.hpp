#pragma once
// Whole-file reads for the mesh readers: gzip-compressed files are inflated
// transparently, and every field read is checked against the data length so
// that a truncated or corrupt file is an InputError, never a wild read.

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"

namespace animrt::seqnet::detail {

// Feature and model files hold every frame or weight uncompressed; meshes
// (OBJ, MD2, MD3) stay within kMaxInputFileBytes, inflated or not.
inline constexpr std::uintmax_t kMaxFeatureFileBytes = std::uintmax_t{1} << 30;  // 1 GiB
inline constexpr std::uintmax_t kMaxModelFileBytes = std::uintmax_t{2} << 30;    // 2 GiB

// The file's bytes through the input checks (read_input_bytes): a regular
// file of at most max_bytes, inflated when it is gzip-compressed, up to
// kMaxInflatedBytes. Throws InputError naming the file.
std::vector<std::uint8_t> read_file_bytes(const std::string& path,
                                          std::uintmax_t max_bytes = kMaxInputFileBytes);

// The file name without a trailing ".gz", lower-cased extension included.
std::string extension_without_gz(const std::string& path);

[[noreturn]] inline void fail(const std::string& file, const std::string& key,
                              const std::string& message) {
  throw InputError(Location{file, 0, 0}, key, message);
}

// Little-endian reads at byte offsets, bounds-checked.
class ByteView {
 public:
  ByteView(const std::vector<std::uint8_t>& bytes, std::string file)
      : bytes_(bytes), file_(std::move(file)) {}

  std::size_t size() const { return bytes_.size(); }
  const std::string& file() const { return file_; }

  // Throws unless [offset, offset + count * item) lies inside the data.
  void need(std::uint64_t offset, std::uint64_t count, std::uint64_t item, const std::string& key,
            const std::string& what) const {
    const std::uint64_t n = bytes_.size();
    check_header_count(file_, key, what, count, item, n);
    if (offset > n || count * item > n - offset) {
      fail(file_, key,
           "file is truncated: " + what + " at byte " + std::to_string(offset) + " needs " +
               std::to_string(count * item) + " bytes, the file has " + std::to_string(n));
    }
  }

  std::int32_t i32(std::uint64_t at) const { return static_cast<std::int32_t>(u32(at)); }
  std::uint32_t u32(std::uint64_t at) const {
    return static_cast<std::uint32_t>(bytes_[at]) |
           static_cast<std::uint32_t>(bytes_[at + 1]) << 8 |
           static_cast<std::uint32_t>(bytes_[at + 2]) << 16 |
           static_cast<std::uint32_t>(bytes_[at + 3]) << 24;
  }
  std::int16_t i16(std::uint64_t at) const {
    return static_cast<std::int16_t>(static_cast<std::uint16_t>(bytes_[at] | bytes_[at + 1] << 8));
  }
  std::uint8_t u8(std::uint64_t at) const { return bytes_[at]; }
  float f32(std::uint64_t at) const {
    const std::uint32_t bits = u32(at);
    float out;
    std::memcpy(&out, &bits, sizeof out);
    return out;
  }
  // A fixed-size, NUL-padded name field.
  std::string name(std::uint64_t at, std::size_t length) const {
    std::string out;
    for (std::size_t i = 0; i < length && bytes_[at + i] != 0; ++i) {
      out.push_back(static_cast<char>(bytes_[at + i]));
    }
    return out;
  }

 private:
  const std::vector<std::uint8_t>& bytes_;
  std::string file_;
};

}  // namespace animrt::seqnet::detail
