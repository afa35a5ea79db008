// Signed broadcasts of a keyed server (robotalk/broadcast_signature.h).
#include "robotalk/broadcast_signature.h"

#include "robotalk/channels.h"
#include "robotalk/request.h"

#include <gtest/gtest.h>

#include "support/test_keys.h"

namespace robotalk {
namespace {

using testing::TestKey;

Nonce NonceOf(std::uint8_t v) {
  Nonce n{};
  n.fill(v);
  return n;
}

std::vector<std::uint8_t> Sample(double x) {
  StateSample s;
  s.robot = "pioneer";
  s.server_time = TimePoint(std::chrono::seconds(100));
  s.sample = 1;
  s.base.x = x;
  return EncodeStateSample(s);
}

TEST(BroadcastSignature, ASignedSampleVerifiesUnderItsKeyChannelAndInstance) {
  const KeyPair server = TestKey(1);
  const BroadcastSigner signer(server, NonceOf(7));
  std::vector<std::uint8_t> bytes = Sample(1.0);
  const std::size_t plain = bytes.size();
  signer.Sign(StateChannel("pioneer"), bytes);
  EXPECT_EQ(bytes.size(), plain + kSignatureSuffixBytes);
  const Nonce instance = NonceOf(7);
  EXPECT_EQ(VerifyBroadcast(StateChannel("pioneer"), bytes, server.public_key, &instance),
            BroadcastVerdict::kAuthentic);
  EXPECT_EQ(WithoutSignature(bytes).size(), plain);
  EXPECT_EQ(DecodeStateSample(bytes).base.x, 1.0) << "readers that do not verify still decode it";
  EXPECT_EQ(VerifySelfSigned(StateChannel("pioneer"), bytes)->server_key, server.public_key);
}

TEST(BroadcastSignature, AForgedOrMovedOrForeignBroadcastIsRefusedWithItsReason) {
  const KeyPair server = TestKey(1);
  const Nonce instance = NonceOf(7);
  const BroadcastSigner signer(server, instance);
  std::vector<std::uint8_t> bytes = Sample(1.0);
  signer.Sign(StateChannel("pioneer"), bytes);

  EXPECT_EQ(VerifyBroadcast(StateChannel("pioneer"), Sample(42.0), server.public_key, &instance),
            BroadcastVerdict::kUnsigned);
  std::vector<std::uint8_t> changed = bytes;
  changed[20] ^= 1;  // a value inside the message
  EXPECT_EQ(VerifyBroadcast(StateChannel("pioneer"), changed, server.public_key, &instance),
            BroadcastVerdict::kForged);
  EXPECT_FALSE(VerifySelfSigned(StateChannel("pioneer"), changed));
  EXPECT_EQ(VerifyBroadcast(StateChannel("arm"), bytes, server.public_key, &instance),
            BroadcastVerdict::kForged)
      << "signed for another channel";
  const Nonce other_instance = NonceOf(8);
  EXPECT_EQ(VerifyBroadcast(StateChannel("pioneer"), bytes, server.public_key, &other_instance),
            BroadcastVerdict::kOtherInstance);
  std::vector<std::uint8_t> mallory = Sample(42.0);
  BroadcastSigner(TestKey(2), instance).Sign(StateChannel("pioneer"), mallory);
  EXPECT_EQ(VerifyBroadcast(StateChannel("pioneer"), mallory, server.public_key, &instance),
            BroadcastVerdict::kOtherKey);
  // Mallory's message claiming the real server's key in its suffix.
  std::copy(server.public_key.bytes.begin(), server.public_key.bytes.end(),
            mallory.end() - kSignatureSuffixBytes + kSignatureMagic.size());
  EXPECT_EQ(VerifyBroadcast(StateChannel("pioneer"), mallory, server.public_key, &instance),
            BroadcastVerdict::kForged);
}

TEST(BroadcastSignature, AnUnsignedMessageIsLeftWhole) {
  const std::vector<std::uint8_t> bytes = Sample(3.0);
  EXPECT_EQ(WithoutSignature(bytes).size(), bytes.size());
  EXPECT_FALSE(SignatureSuffix(bytes));
}

}  // namespace
}  // namespace robotalk
