#include "animrt/runtime/osc_receiver.hpp"

namespace animrt {

OscReceiver::OscReceiver(const std::string& host, int port, Handler handler)
    : handler_(std::move(handler)),
      udp_("OSC", host, port,
           [this](std::span<const std::uint8_t> datagram, const UdpSender&) { take(datagram); }) {}

void OscReceiver::take(std::span<const std::uint8_t> datagram) {
  messages_buffer_.clear();
  if (!parse_osc_packet(datagram, messages_buffer_)) {
    malformed_.fetch_add(1);
    return;
  }
  for (const OscMessage& message : messages_buffer_) {
    messages_.fetch_add(1);
    if (!handler_(message)) unknown_.fetch_add(1);
  }
}

}  // namespace animrt
