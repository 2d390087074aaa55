#include "file_bytes.hpp"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace animrt::seqnet::detail {

std::vector<std::uint8_t> read_file_bytes(const std::string& path, std::size_t max_bytes) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail(path, "", "is a folder, not a file");
  // gzopen reads plain files unchanged, so one path serves both.
  gzFile in = gzopen(path.c_str(), "rb");
  if (in == nullptr) fail(path, "", "cannot open");
  std::vector<std::uint8_t> out;
  std::vector<std::uint8_t> chunk(1 << 16);
  for (;;) {
    const int n = gzread(in, chunk.data(), static_cast<unsigned>(chunk.size()));
    if (n < 0) {
      int code = 0;
      const std::string message = gzerror(in, &code);
      gzclose(in);
      fail(path, "", "cannot read (" + message + ")");
    }
    if (n == 0) break;
    if (out.size() + static_cast<std::size_t>(n) > max_bytes) {
      gzclose(in);
      fail(path, "", "is larger than " + std::to_string(max_bytes) + " bytes");
    }
    out.insert(out.end(), chunk.begin(), chunk.begin() + n);
  }
  int code = Z_OK;
  const std::string message = gzerror(in, &code);
  const int closed = gzclose(in);
  if (code != Z_OK && code != Z_STREAM_END) fail(path, "", "broken gzip data (" + message + ")");
  if (closed == Z_BUF_ERROR) fail(path, "", "gzip data is truncated");
  if (closed != Z_OK) fail(path, "", "cannot read");
  return out;
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
