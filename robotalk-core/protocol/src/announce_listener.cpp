#include "robotalk/announce_listener.h"

#include "robotalk/channels.h"

#include <chrono>
#include <utility>

namespace robotalk {

AnnounceListener::AnnounceListener(std::unique_ptr<Transport> transport, std::optional<PublicKey> only,
                                   OnHeard on_heard)
    : transport_(std::move(transport)), only_(std::move(only)), on_heard_(std::move(on_heard)) {
  subscription_ = transport_->Subscribe(
      kAnnounceChannel, [this](const std::string&, std::span<const std::uint8_t> bytes) {
        const std::optional<HeardAnnouncement> heard = HearAnnouncement(bytes, only_ ? &*only_ : nullptr);
        if (heard)
          on_heard_(*heard);
        else
          ++dropped_;
      });
  thread_ = std::thread([this] { Listen(); });
}

AnnounceListener::~AnnounceListener() {
  stop_ = true;
  thread_.join();
}

void AnnounceListener::Listen() {
  // A short wait bounds how long the destructor waits for this thread.
  while (!stop_) {
    try {
      transport_->HandleFor(std::chrono::milliseconds(100));
    } catch (const TransportError&) {
      // the transport failed to receive: try again, without spinning
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  subscription_.reset();  // on the dispatching thread (transport.h)
}

}  // namespace robotalk
