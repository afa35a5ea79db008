// A Transport that passes every call to another one: a test derives from it
// and overrides only the call it delays or alters (a starved read thread, a
// late handler), so the socket's stamp (ReceiveTime) stays the inner one's.
#pragma once

#include "robotalk/transport.h"

#include <memory>
#include <string>
#include <utility>

namespace robotalk::testing {

class ForwardingTransport : public Transport {
 public:
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

}  // namespace robotalk::testing
