// ForwardingTransport: a Transport that passes every call to another one. A
// wrapper derives from it and overrides only what it changes — a URL it
// names differently (OpenLcmTransport's single layout), a read thread a test
// starves, a handler it delays — so everything else, the socket's receive
// stamp (ReceiveTime) above all, stays the inner transport's.
#pragma once

#include "robotalk/transport.h"

#include <memory>
#include <string>
#include <utility>

namespace robotalk {

class ForwardingTransport : public Transport {
 public:
  /// `inner` must outlive this transport. It may be a member of a derived
  /// class not yet constructed: the reference is only kept here, never used.
  explicit ForwardingTransport(Transport& inner) : inner_(inner) {}
  void Publish(const std::string& channel, std::span<const std::uint8_t> bytes) override {
    inner_.Publish(channel, bytes);
  }
  std::unique_ptr<Subscription> Subscribe(const std::string& channel_regex, Handler handler) override {
    return inner_.Subscribe(channel_regex, std::move(handler));
  }
  int HandleFor(Duration timeout) override { return inner_.HandleFor(timeout); }
  int fileno() const override { return inner_.fileno(); }
  std::string url() const override { return inner_.url(); }
  WallTime ReceiveTime() const override { return inner_.ReceiveTime(); }

 protected:
  Transport& inner() { return inner_; }

 private:
  Transport& inner_;
};

}  // namespace robotalk
