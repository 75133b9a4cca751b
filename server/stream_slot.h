#ifndef CABLESIM_SERVER_STREAM_SLOT_H_
#define CABLESIM_SERVER_STREAM_SLOT_H_

// The service's stream bookkeeping, shared by the RPCs of
// cablesim_service.cc and couple_service.cc: StreamSlot (a place among the
// limited streams, and the stall watchdog's registration) and TimedWrite.

#include <chrono>
#include <cstdint>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "server/cablesim_service.h"

namespace cablesim {

// A steady clock in nanoseconds (the watchdog's).
inline int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Holds one of the limited stream slots and registers the stream with the
// stall watchdog.
class StreamSlot {
 public:
  // `counted`: the stream takes one of the max_streams slots (runs do;
  // watchers and result downloads only register with the watchdog).
  // A counted stream also takes one of its client's max_streams_per_peer
  // slots (`client`: ClientKey), so that one client cannot hold every slot.
  StreamSlot(CablesimServiceImpl* service, grpc::ServerContext* context, bool counted = true,
             const std::string& client = "")
      : service_(service), watch_{context}, counted_(counted) {
    watch_.counted = counted_;
    if (counted_) peer_ = client.empty() ? PeerOf(context) : client;
    absl::MutexLock lock(&service_->mu_);
    if (counted_) {
      const ServerLimits& limits = service_->limits_;
      int& mine = service_->peer_streams_[peer_];
      // Streams whose clients stopped reading count against those clients
      // only (CablesimServiceImpl::kStalledAfterNs).
      int stalled = 0;
      const int64_t now = NowNs();
      for (const auto& [watch, unused] : service_->watched_) {
        const int64_t started = watch->write_started_ns.load();
        stalled += watch->counted && started != 0 &&
                   now - started > CablesimServiceImpl::kStalledAfterNs;
      }
      // The client's own share first: a client that holds it (reading or
      // not) is told so.
      if (mine >= limits.max_streams_per_peer) {
        refusal_ = absl::StrCat("this client (", peer_, ") already runs ", mine,
                                " streams, the server's limit is ", limits.max_streams_per_peer,
                                " (max_streams_per_peer); try again later");
      } else if (service_->streams_ - stalled >= limits.max_streams ||
                 service_->streams_ >= 2 * static_cast<int64_t>(limits.max_streams)) {
        refusal_ = absl::StrCat("the server already runs ", limits.max_streams,
                                " streams (max_streams); try again later");
      }
      acquired_ = refusal_.empty();
      if (acquired_) {
        ++service_->streams_;
        ++mine;
      } else if (mine == 0) {
        service_->peer_streams_.erase(peer_);
      }
    } else {
      acquired_ = true;
    }
    service_->watched_[&watch_] = true;
  }
  ~StreamSlot() {
    absl::MutexLock lock(&service_->mu_);
    if (counted_ && acquired_) {
      --service_->streams_;
      if (--service_->peer_streams_[peer_] == 0) service_->peer_streams_.erase(peer_);
    }
    service_->watched_.erase(&watch_);
  }
  bool acquired() const { return acquired_; }
  // Why not acquired (names the limit).
  const std::string& refusal() const { return refusal_; }

  // "ipv4:127.0.0.1:5555" -> "ipv4:127.0.0.1", "ipv6:[::1]:5555" -> "ipv6:[::1]".
  static std::string PeerOf(const grpc::ServerContext* context) {
    std::string peer = context->peer();
    const size_t colon = peer.rfind(':');
    if ((peer.rfind("ipv4:", 0) == 0 || peer.rfind("ipv6:", 0) == 0) && colon > 5) {
      peer.resize(colon);
    }
    return peer;
  }
  CablesimServiceImpl::StreamWatch* watch() { return &watch_; }

 private:
  CablesimServiceImpl* service_;
  CablesimServiceImpl::StreamWatch watch_;
  const bool counted_;
  bool acquired_ = false;
  std::string peer_;
  std::string refusal_;
};

// Writes `event` to `writer` (any gRPC server stream), recording the wait
// for the watchdog.
template <typename Writer, typename Message>
bool TimedWrite(Writer* writer, const Message& event, CablesimServiceImpl::StreamWatch* watch) {
  watch->write_started_ns = NowNs();
  const bool ok = writer->Write(event);
  watch->write_started_ns = 0;
  return ok;
}

}  // namespace cablesim

#endif  // CABLESIM_SERVER_STREAM_SLOT_H_
