#pragma once
// The --dashboard HOST:PORT option of run, evolve and herd, checked before the
// work starts: a bad address, or a non-loopback one without
// --dashboard-remote, is one line on stderr and a usage error.

#include <optional>
#include <string>
#include <utility>

namespace animrt::cli {

struct DashboardAddress {
  bool ok = true;  // false: the error is printed, exit with a usage error
  std::optional<std::pair<std::string, int>> at;  // none when `text` is empty
};

DashboardAddress check_dashboard_address(const std::string& text, bool remote);

}  // namespace animrt::cli
