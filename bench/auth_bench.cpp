// Google Benchmark of package authentication (robotalk/session_auth.h): what
// keyed mode adds per package on the client (seal) and the server (verify:
// the MAC; the session lookup and window are the server's session table), for a 200-byte package (a few
// set-points) and a 30 kB one (a long playback batch); and the handshake,
// paid once per session. Figures: docs/security.md, "Cost".
//   robotalk-auth-bench [--benchmark_format=json ...]
#include "robotalk/session_auth.h"

#include "bench_keys.h"

#include <benchmark/benchmark.h>

#include <vector>

namespace {

using namespace robotalk;

using bench::Identity;

struct Fixture {
  KeyPair client = Identity(1);
  AccessList access = AccessList::Parse(Identity(1).public_key.ToString() + " alice *=all\n", "bench");
  ServerAuthenticator server{Identity(2), access, RandomNonce()};
  SessionKeys keys;
  SessionKeys server_keys;
  Fixture() {
    const ClientHandshake hs(client, KeyedClientId(client.public_key, 42));
    const HelloAccepted accepted = Answer(hs.hello());
    server_keys = accepted.keys;
    keys = hs.Finish(accepted.answer);
  }
  HelloAccepted Answer(const ClientHello& hello) const {
    HelloResult result = server.Answer(hello);
    if (!std::holds_alternative<HelloAccepted>(result)) throw Error(std::get<HelloRefused>(result).why);
    return std::get<HelloAccepted>(std::move(result));
  }
};

std::vector<std::uint8_t> Bytes(std::size_t n) {
  std::vector<std::uint8_t> b(n);
  for (std::size_t i = 0; i < n; ++i) b[i] = static_cast<std::uint8_t>(i * 13 + 1);
  return b;
}

// Client: MAC of one package.
void BM_SealPackage(benchmark::State& state) {
  Fixture f;
  const auto bytes = Bytes(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state)
    benchmark::DoNotOptimize(ComputeMac(f.keys.client_to_server, f.keys.session_id, bytes));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_SealPackage)->Arg(200)->Arg(30000);

// Server: the whole per-package check. Each iteration verifies a package with
// a new sequence number (MACs prepared outside the timed loop), so every one
// takes the accept path.
void BM_VerifyPackage(benchmark::State& state) {
  Fixture f;
  constexpr int kPrepared = 4096;
  const auto size = static_cast<std::size_t>(state.range(0));
  std::vector<std::vector<std::uint8_t>> packages(kPrepared, Bytes(size));
  std::vector<Mac> macs(kPrepared);
  std::int64_t sequence = 0;
  auto prepare = [&] {
    for (int i = 0; i < kPrepared; ++i) {
      const std::int64_t s = sequence + 1 + i;
      for (int b = 0; b < 8; ++b)
        packages[static_cast<std::size_t>(i)][static_cast<std::size_t>(b)] =
            static_cast<std::uint8_t>(s >> (8 * b));
      macs[static_cast<std::size_t>(i)] =
          ComputeMac(f.keys.client_to_server, f.keys.session_id, packages[static_cast<std::size_t>(i)]);
    }
  };
  int next = kPrepared;
  for (auto _ : state) {
    if (next == kPrepared) {
      state.PauseTiming();
      prepare();
      next = 0;
      state.ResumeTiming();
    }
    ++sequence;
    if (!ServerAuthenticator::Verify(f.server_keys, packages[static_cast<std::size_t>(next)],
                                     macs[static_cast<std::size_t>(next)])) {
      state.SkipWithError("MAC refused");
    }
    ++next;
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_VerifyPackage)->Arg(200)->Arg(30000);

// Once per session: hello (sign), answer (verify, kx, sign), finish (verify, kx).
void BM_Handshake(benchmark::State& state) {
  Fixture f;
  for (auto _ : state) {
    const ClientHandshake hs(f.client, KeyedClientId(f.client.public_key, 42));
    const SessionKeys keys = hs.Finish(f.Answer(hs.hello()).answer);
    benchmark::DoNotOptimize(keys.session_id);
  }
}
BENCHMARK(BM_Handshake);

// What a hello from a listed key costs the server before it can refuse a bad
// signature: one Ed25519 verification (a flood of forged hellos costs this each).
void BM_VerifyHelloSignature(benchmark::State& state) {
  Fixture f;
  const ClientHandshake hs(f.client, 42);
  const auto signed_bytes = hs.hello().SignedBytes();
  for (auto _ : state) {
    benchmark::DoNotOptimize(VerifySignature(hs.hello().client_key, signed_bytes, hs.hello().signature));
  }
}
BENCHMARK(BM_VerifyHelloSignature);

}  // namespace

BENCHMARK_MAIN();
