#ifndef CABLESIM_SERVER_LISTEN_ADDRESS_H_
#define CABLESIM_SERVER_LISTEN_ADDRESS_H_

// The --listen address, resolved once before any check: a host name is
// looked up here, the server binds the address it resolved to (so a name
// cannot pass the loopback check and then bind something else), and
// "local" means an address that is loopback after resolution (127.0.0.0/8,
// ::1, ::ffff:127.x.y.z) or a unix socket, never a name that looks local.

#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace cablesim {

struct ListenAddress {
  // What to bind: "127.0.0.1:50051", "[::1]:0", "0.0.0.0:50051",
  // "unix:/path" (a unix socket, unchanged).
  std::string bind;
  // Only loopback (or a unix socket) can reach it.
  bool loopback = false;
};

// Numeric addresses ("127.0.0.1", "::1") a host resolves to, in the
// resolver's order; empty when it resolves to none.
using HostResolver = std::function<absl::StatusOr<std::vector<std::string>>(const std::string&)>;

// getaddrinfo (AF_UNSPEC, the system's order).
absl::StatusOr<std::vector<std::string>> ResolveHost(const std::string& host);

// Parses `listen` (HOST:PORT, [IPV6]:PORT or unix:PATH) and resolves HOST
// with `resolver` (the first address it gives is the one bound).
// InvalidArgument naming --listen for a malformed address or a name that
// resolves to nothing.
absl::StatusOr<ListenAddress> ResolveListenAddress(const std::string& listen,
                                                   const HostResolver& resolver = ResolveHost);

// Whether a numeric IPv4 or IPv6 address is loopback.
bool IsLoopbackAddress(const std::string& numeric);

}  // namespace cablesim

#endif  // CABLESIM_SERVER_LISTEN_ADDRESS_H_
