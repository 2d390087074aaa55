#pragma once
// The bus key `device_watchdog_ms`: how long a device may hear nothing from
// the host before it stops its actuators by itself (the host died: kill -9, a
// crash, a power cut). Each protocol with such a guard reads it in its own
// unit; the others refuse the key.

#include <string_view>

#include "animrt/core/yaml_doc.hpp"

namespace animrt {

inline constexpr std::string_view kDeviceWatchdogKey = "device_watchdog_ms";

// The default: the larger of 100 ms and 5 loop periods. Not shorter: a host
// that is not real-time (no SCHED_FIFO, a busy desktop, a USB adapter's or a
// pty's bytes held up in the kernel) misses a few periods now and then, and
// every such hiccup would stop the figure; 100 ms is also how long the
// runtime itself lets a device go unanswered before it faults it
// (safety.watchdog_timeout_s), so the devices give up on the host no sooner
// than the host gives up on them. 0 (unknown period) counts as no period.
double default_device_watchdog_ms(double loop_period_s);

// Reads `device_watchdog_ms` of a bus node: absent -> the default, `off` or 0
// -> 0 (no guard), a number of milliseconds within what the device can hold
// (unit_ms .. max_ms) -> itself. Every result but 0 is rounded up to a whole
// number of unit_ms (a guard may be later than asked, never earlier); a
// default beyond max_ms is max_ms. Anything else fails at the key.
double read_device_watchdog_ms(const YamlNode& bus_node, double loop_period_s, double unit_ms,
                               double max_ms, std::string_view device);

// For a bus whose devices have no guard: fails at the key if it is set.
void refuse_device_watchdog(const YamlNode& bus_node, std::string_view why);

}  // namespace animrt
