#pragma once
// The dashboards' HTTP server: httplib's request handling, with connections
// handled so that no client can take the controls away.
//
// httplib serves every connection from one fixed pool (8 threads here): an
// event stream holds its thread for as long as it is open, and so does a
// client that sends its headers a byte at a time, so eight of either left
// POST /api/stop waiting in the queue for as long as they stayed. Here each
// connection gets a thread of its own (up to kMaxConnections, beyond which a
// connection is answered 503 at once), so a stop is handled as soon as it
// arrives whatever else is open. A separate pool for controls was the other
// choice; it needs the request read before it can be told apart, which is
// the very wait a slow client imposes, so it would still need this.
//
// A request (its line, headers and body) must arrive whole within
// kRequestTimeout of its first byte, or the connection is dropped: a client
// that sends its headers slowly holds a thread for that long at most. A
// POST without Content-Length or Transfer-Encoding has an empty body
// (RFC 9112 6.3), where httplib would read until the connection closes.
// stop() wakes every open connection, so the server ends at once.
//
// A body is at most kMaxBody (the controls take a few bytes of JSON; a
// longer Content-Length is answered 413), and a request at most
// kMaxRequestBytes read from its socket, whatever it declares (httplib
// enforces no limit on a chunked body): httplib reads a body before any
// handler sees the request, so a client without the token held gigabytes
// of memory per connection until its deadline.

#include <httplib.h>

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <set>

namespace animrt {

class DashboardHttpServer : public httplib::Server {
 public:
  static constexpr int kMaxConnections = 256;
  static constexpr std::chrono::milliseconds kRequestTimeout{2000};
  static constexpr std::size_t kMaxBody = 64 * 1024;
  static constexpr std::size_t kMaxRequestBytes = kMaxBody + 64 * 1024;  // + head, chunk sizes

  DashboardHttpServer();

  // Connections being served now.
  int connections() const;

  // Ends the listening thread whenever it is called. httplib's stop() does
  // nothing until that thread has set its running flag, so a stop that comes
  // first (a run that ends at once) would leave it accepting for ever.
  void close_listener();

 private:
  class ConnectionThreads;
  class ConnectionStream;

  bool process_and_close_socket(socket_t sock) override;
  void serve(socket_t sock);
  bool track(socket_t sock);
  void untrack(socket_t sock);
  // Wakes every open connection (they end); later ones close at once.
  void wake_all();

  mutable std::mutex mutex_;
  std::set<socket_t> open_;
  bool waking_ = false;
};

}  // namespace animrt
