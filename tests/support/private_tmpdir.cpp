// Every test process gets a temporary directory of its own. ctest runs the
// tests of one binary as parallel processes, so a fixed file name under /tmp
// (::testing::TempDir(), std::filesystem::temp_directory_path()) would be
// written by two tests at once. TEST_TMPDIR steers the former, TMPDIR the
// latter and any program a test starts.

#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

struct PrivateTmpDir {
  std::string path;

  PrivateTmpDir() {
    const char* base = std::getenv("TMPDIR");
    std::string pattern =
        std::string(base != nullptr && *base != '\0' ? base : "/tmp") + "/animrt_test_XXXXXX";
    if (::mkdtemp(pattern.data()) == nullptr) return;  // keep the shared one
    path = pattern;
    ::setenv("TEST_TMPDIR", path.c_str(), 1);
    ::setenv("TMPDIR", path.c_str(), 1);
  }
  ~PrivateTmpDir() {
    if (path.empty()) return;
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  PrivateTmpDir(const PrivateTmpDir&) = delete;
  PrivateTmpDir& operator=(const PrivateTmpDir&) = delete;
};

const PrivateTmpDir private_tmpdir;

}  // namespace
