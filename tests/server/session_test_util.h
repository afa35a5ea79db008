// Opening a protocol-2 session in ServerDaemon tests: a hello on the
// in-memory bus, the server stepped, the answer read back.
#pragma once

#include "robotalk/channels.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"

#include <functional>
#include <optional>
#include <string>

namespace robotalk::testing {

/// Says hello (open mode unless `hello` is given) for `robot` as `client_id`
/// and returns the answer; `step` runs the server once. Throws when no answer came.
inline HelloAnswer SayHello(MemoryTransport& client, const std::string& robot, std::int64_t client_id,
                            const std::function<void()>& step, std::optional<Hello> hello = std::nullopt) {
  std::optional<HelloAnswer> answer;
  auto sub = client.Subscribe(
      HelloAnswerChannel(robot, client_id),
      [&](const std::string&, std::span<const std::uint8_t> b) { answer = DecodeHelloAnswer(b); });
  if (!hello) {
    hello = Hello{};
    hello->body.client_id = client_id;
    hello->body.client_nonce = RandomNonce();
  }
  client.Publish(HelloChannel(robot), EncodeHello(*hello));
  step();
  client.HandleFor(Duration(0));
  if (!answer) throw Error("SayHello: no answer from robot '" + robot + "'");
  return *answer;
}

}  // namespace robotalk::testing
