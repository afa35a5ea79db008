// The clock offset comes from when a reply reached the socket, not from when
// the client got round to reading it: a loaded client that reads every
// message 20 ms late still measures the server's clock right.
//
// Real server core (kinematic driver) and client in one process on a
// MemoryBus, both on the steady clock, so the true offset is zero.
#include "kinematic_driver.h"
#include "robotalk/forwarding_transport.h"
#include "robotalk/memory_transport.h"
#include "robotalk/robot_client.h"
#include "robotalk/server.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

// Reads every message `lag` after it was ready (a client whose read thread
// is starved); the socket's stamp, ReceiveTime(), still says when it came.
class SlowReaderTransport final : public ForwardingTransport {
 public:
  SlowReaderTransport(Transport& inner, Duration lag) : ForwardingTransport(inner), lag_(lag) {}
  int HandleFor(Duration timeout) override {
    std::this_thread::sleep_for(lag_);
    return inner().HandleFor(timeout);
  }

 private:
  Duration lag_;
};

TEST(SlowReaderClock, TheOffsetAndRoundTripComeFromTheSocketsStampNotFromWhenTheReplyWasRead) {
  DriverRegistry registry;
  RegisterKinematicDriver(registry);
  auto bus = std::make_shared<MemoryBus>();
  MemoryTransport server_end(bus), client_end(bus);
  SlowReaderTransport slow_client(client_end, milliseconds(20));
  SteadyClock clock;
  ServerOptions server_options;
  server_options.precise_timing = false;
  Server server(
      server_end, server_options,
      {RobotSpec{"pioneer", "kinematic", std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {}}},
      registry, clock);
  server.Start();
  {
    ClientOptions options;
    options.transport = &slow_client;  // and the default (steady) clock: the server's
    options.timeout = seconds(5);
    options.connect_timeout = seconds(5);
    RobotClient client(options);
    client.Connect("pioneer");
    for (int i = 0; i < 5; ++i) ASSERT_EQ(client.SetJoint("pan", {0.01 * i}).signal, Signal::kSuccess);
    // Read at handling time, every sample's round trip would be 20 ms longer
    // and the offset 10 ms off (half the lag): both were, before.
    EXPECT_LT(client.clock_round_trip(), milliseconds(10));
    EXPECT_LT(std::chrono::abs(client.clock_offset()), milliseconds(5));
  }
  server.Stop();
}

}  // namespace
}  // namespace robotalk
