#include "file_bytes.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace animrt::seqnet::detail {

std::vector<std::uint8_t> read_file_bytes(const std::string& path, std::uintmax_t max_bytes) {
  return read_input_bytes(path, max_bytes, kMaxInflatedBytes);
}

std::string extension_without_gz(const std::string& path) {
  std::filesystem::path p(path);
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".gz") return extension_without_gz(p.replace_extension().string());
  return ext;
}

}  // namespace animrt::seqnet::detail
