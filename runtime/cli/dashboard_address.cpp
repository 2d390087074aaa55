// The --dashboard option of run, evolve and herd (see dashboard_address.hpp).

#include "dashboard_address.hpp"

#include <iostream>
#include <stdexcept>

#include "animrt/runtime/dashboard.hpp"

namespace animrt::cli {

DashboardAddress check_dashboard_address(const std::string& text, bool remote) {
  DashboardAddress out;
  if (text.empty()) return out;
  try {
    out.at = parse_host_port(text);
  } catch (const std::invalid_argument& e) {
    std::cerr << "--dashboard: " << e.what() << '\n';
    out.ok = false;
    return out;
  }
  if (!remote && !is_loopback_host(out.at->first)) {
    std::cerr << "--dashboard: " << out.at->first
              << " is not a loopback address (127.0.0.1, [::1] or localhost); the dashboard "
                 "takes controls, so serving other machines needs --dashboard-remote\n";
    out.ok = false;
  }
  return out;
}

}  // namespace animrt::cli
