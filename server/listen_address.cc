#include "server/listen_address.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cstring>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"

namespace cablesim {
namespace {

absl::Status Bad(const std::string& listen, const std::string& why) {
  return absl::InvalidArgumentError(absl::StrCat("--listen ", listen, ": ", why));
}

}  // namespace

absl::StatusOr<std::vector<std::string>> ResolveHost(const std::string& host) {
  addrinfo hints;
  std::memset(&hints, 0, sizeof(hints));
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (const int rc = getaddrinfo(host.c_str(), nullptr, &hints, &found); rc != 0) {
    return absl::NotFoundError(absl::StrCat("cannot resolve \"", host, "\": ", gai_strerror(rc)));
  }
  std::vector<std::string> addresses;
  for (const addrinfo* a = found; a != nullptr; a = a->ai_next) {
    char text[INET6_ADDRSTRLEN] = {0};
    if (a->ai_family == AF_INET) {
      inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(a->ai_addr)->sin_addr, text,
                sizeof(text));
    } else if (a->ai_family == AF_INET6) {
      inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6*>(a->ai_addr)->sin6_addr, text,
                sizeof(text));
    } else {
      continue;
    }
    addresses.push_back(text);
  }
  freeaddrinfo(found);
  return addresses;
}

bool IsLoopbackAddress(const std::string& numeric) {
  in_addr v4;
  if (inet_pton(AF_INET, numeric.c_str(), &v4) == 1) {
    return (ntohl(v4.s_addr) >> 24) == 127;
  }
  in6_addr v6;
  if (inet_pton(AF_INET6, numeric.c_str(), &v6) == 1) {
    if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
    return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
  }
  return false;
}

absl::StatusOr<ListenAddress> ResolveListenAddress(const std::string& listen,
                                                   const HostResolver& resolver) {
  if (absl::StartsWith(listen, "unix:") || absl::StartsWith(listen, "unix-abstract:")) {
    return ListenAddress{listen, true};
  }
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos) return Bad(listen, "expected HOST:PORT");
  std::string host = listen.substr(0, colon);
  const std::string port = listen.substr(colon + 1);
  int port_number = 0;
  if (!absl::SimpleAtoi(port, &port_number) || port_number < 0 || port_number > 65535) {
    return Bad(listen, "the port must be a number from 0 to 65535");
  }
  if (absl::StartsWith(host, "[")) {
    if (!absl::EndsWith(host, "]")) return Bad(listen, "expected [IPV6]:PORT");
    host = host.substr(1, host.size() - 2);
  }
  if (host.empty()) return Bad(listen, "no host (write 0.0.0.0:PORT or [::]:PORT for all)");
  absl::StatusOr<std::vector<std::string>> addresses = resolver(host);
  if (!addresses.ok()) return Bad(listen, std::string(addresses.status().message()));
  if (addresses->empty()) return Bad(listen, absl::StrCat("\"", host, "\" resolves to no address"));
  const std::string& address = addresses->front();
  ListenAddress result;
  result.loopback = IsLoopbackAddress(address);
  result.bind = absl::StrContains(address, ':') ? absl::StrCat("[", address, "]:", port)
                                                 : absl::StrCat(address, ":", port);
  return result;
}

}  // namespace cablesim
