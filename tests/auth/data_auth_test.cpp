// Every datum vouched for (auth/data_auth.hpp): a message vouched by an allowed publisher is
// accepted by each reader the lab names and by no one else; unsigned, malformed, not-allowed,
// tampered, replayed and stale ones are refused with their verdict, 10,000 each; a reader cannot
// forge what a publisher says to another reader; the pair keys against an independent BLAKE2b.

#include "auth/data_auth.hpp"

#include <gtest/gtest.h>
#include <sodium.h>

#include <random>

#include "tests/support/manual_clock.hpp"

namespace sg::auth {
namespace {

constexpr int kTrials = 10'000;
constexpr int64_t kT0 = 1'780'000'000'000'000;  // µs since the epoch (2026)

/// The test's clock, at kT0 unless moved.
struct ManualClock : test::ManualClock {
  ManualClock() : test::ManualClock(kT0) {}
};

LabKey key_of(uint8_t seed) {
  std::array<uint8_t, LabKey::kSize> b{};
  for (size_t i = 0; i < b.size(); ++i) b[i] = static_cast<uint8_t>(seed + 7 * i);
  return LabKey(b);
}

/// The guards of a small lab, all on one manual clock.
struct Lab {
  LabKey key = key_of(1);
  ManualClock clock;
  DataGuard predictor{credentials_from_lab_key(key, "sg-predictor"), {}, clock, 11};
  DataGuard grasp{credentials_from_lab_key(key, "sg-grasp"), {}, clock, 12};
  DataGuard viewer{credentials_from_lab_key(key, "sg-viewer"), {}, clock, 13};
  DataGuard vision{credentials_from_lab_key(key, "sg-vision"), {}, clock, 14};
};

std::vector<uint8_t> payload(size_t n = 200, uint8_t seed = 3) {
  std::vector<uint8_t> p(n);
  for (size_t i = 0; i < n; ++i) p[i] = static_cast<uint8_t>(seed * 31 + i);
  return p;
}

GuardVerdict verdict(DataGuard& reader, const std::string& channel,
                     const std::vector<uint8_t>& bytes, int64_t now = kT0) {
  return reader.check(channel, bytes.data(), bytes.size(), now).verdict;
}

// A trajectory vouched for by sg-predictor is accepted by sg-grasp and sg-viewer (its readers),
// with the payload's size; the same bytes on another channel, or at sg-vision, are not.
TEST(DataAuth, AllowedPublisherIsBelievedByItsReaders) {
  Lab lab;
  std::vector<uint8_t> m = payload();
  lab.predictor.vouch("OBJECT_TRAJECTORY", m);
  const GuardResult r = lab.grasp.check("OBJECT_TRAJECTORY", m.data(), m.size(), kT0);
  ASSERT_TRUE(r.accepted()) << r.reason;
  EXPECT_EQ(r.payload_size, 200u);
  EXPECT_EQ(r.sender, "sg-predictor");
  EXPECT_EQ(verdict(lab.viewer, "OBJECT_TRAJECTORY", m), GuardVerdict::kAccepted);
  EXPECT_EQ(verdict(lab.grasp, "OBJECT_POSITION", m), GuardVerdict::kNotAllowed);
  EXPECT_EQ(verdict(lab.vision, "OBJECT_TRAJECTORY", m), GuardVerdict::kNotAllowed);
}

// sg-vision (a lab process with the lab's key, but not allowed on OBJECT_TRAJECTORY) cannot make
// sg-grasp believe a trajectory: refused as not allowed, 10,000 times, each a new counter.
TEST(DataAuth, ProcessNotAllowedOnAChannelIsRefused) {
  Lab lab;
  for (int i = 0; i < kTrials; ++i) {
    std::vector<uint8_t> m = payload(100, static_cast<uint8_t>(i));
    lab.vision.vouch("OBJECT_TRAJECTORY", m);
    ASSERT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kNotAllowed);
  }
  EXPECT_EQ(lab.grasp.count(GuardVerdict::kNotAllowed), kTrials);
  EXPECT_EQ(lab.grasp.count(GuardVerdict::kAccepted), 0);
}

// Unsigned bytes, bytes ending in the magic but no trailer, and trailers claiming sg-predictor
// with random tags (a forger without the key): 10,000 each, none accepted.
TEST(DataAuth, UnsignedMalformedAndForgedAreRefused) {
  Lab lab;
  std::mt19937 rng(5);
  for (int i = 0; i < kTrials; ++i) {
    std::vector<uint8_t> m = payload(64, static_cast<uint8_t>(i));
    ASSERT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kUnsigned);
    std::vector<uint8_t> magic = m;
    magic.insert(magic.end(), {'S', 'G', 'v', '1'});
    ASSERT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", magic), GuardVerdict::kMalformed);
    VouchTrailer forged{"sg-predictor", static_cast<uint32_t>(rng()), kT0 + i, {{"sg-grasp", {}}}};
    for (auto& b : forged.tags[0].tag) b = static_cast<uint8_t>(rng());
    append_vouch_trailer(m, forged);
    ASSERT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kBadTag);
  }
  EXPECT_EQ(lab.grasp.count(GuardVerdict::kAccepted), 0);
}

// Any one byte changed after vouching is refused: in the payload, the sender, instance, counter,
// this reader's tag entry or the trailer's end (the other reader's entry is that reader's affair).
TEST(DataAuth, AnyChangedByteIsRefused) {
  Lab lab;
  std::vector<uint8_t> m = payload(300);
  lab.predictor.vouch("OBJECT_TRAJECTORY", m);
  const size_t others = 300 + (1 + 12 + 4 + 8 + 1) + (1 + 8 + 16);  // sg-viewer's entry starts
  const size_t end = m.size() - 6;
  for (size_t i = 0; i < m.size(); ++i) {
    if (i >= others && i < end) continue;
    std::vector<uint8_t> changed = m;
    changed[i] ^= 0x01;
    ASSERT_NE(verdict(lab.grasp, "OBJECT_TRAJECTORY", changed), GuardVerdict::kAccepted) << i;
  }
  EXPECT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kAccepted);
}

// A reader cannot forge: sg-viewer holds K(sg-predictor -> sg-viewer) but not the key of
// sg-grasp's tag; a trajectory it makes with its own key in sg-grasp's tag is refused.
TEST(DataAuth, AReaderCannotForgeForAnotherReader) {
  Lab lab;
  const Credentials viewer = credentials_from_lab_key(lab.key, "sg-viewer");
  const Peer* from_predictor = nullptr;
  for (const Peer& p : viewer.receive)
    if (p.name == "sg-predictor") from_predictor = &p;
  ASSERT_NE(from_predictor, nullptr);
  std::vector<uint8_t> m = payload();
  VouchTrailer t{"sg-predictor", 99, kT0, {{"sg-grasp", {}}}};
  t.tags[0].tag = vouch_tag(from_predictor->key, "OBJECT_TRAJECTORY", t, m.data(), m.size());
  append_vouch_trailer(m, t);
  EXPECT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kBadTag);
}

// Another lab's key, and a message whose tag is not for this reader, are refused.
TEST(DataAuth, AnotherLabsKeyAndNoTagAreRefused) {
  Lab lab;
  ManualClock clock;
  DataGuard other(credentials_from_lab_key(key_of(2), "sg-predictor"), {}, clock, 1);
  std::vector<uint8_t> m = payload();
  other.vouch("OBJECT_TRAJECTORY", m);
  EXPECT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kBadTag);
  std::vector<uint8_t> p = payload();
  lab.vision.vouch("OBJECT_POSITION", p);  // for sg-predictor and sg-viewer
  EXPECT_EQ(verdict(lab.predictor, "OBJECT_POSITION", p), GuardVerdict::kAccepted);
  std::vector<uint8_t> s = payload();
  lab.predictor.vouch("PROCESS_STATUS", s);
  DataGuard stranger(Credentials{"sg-intruder", {}, {}, {}}, {}, lab.clock, 2);
  EXPECT_EQ(verdict(stranger, "PROCESS_STATUS", s), GuardVerdict::kNotAllowed);
  Credentials untagged = credentials_from_lab_key(lab.key, "sg-vision");
  untagged.send.clear();  // vouches as sg-vision, but for no reader
  DataGuard quiet(untagged, {}, lab.clock, 3);
  std::vector<uint8_t> q = payload();
  quiet.vouch("OBJECT_POSITION", q);
  EXPECT_EQ(verdict(lab.predictor, "OBJECT_POSITION", q), GuardVerdict::kNoTag);
}

// The same bytes again are a replay, 10,000 times; a newer message after them is accepted, and
// replays never lock the sender out.
TEST(DataAuth, ReplaysAreRefusedAndDoNotLockOut) {
  Lab lab;
  std::vector<uint8_t> m = payload();
  lab.predictor.vouch("OBJECT_TRAJECTORY", m);
  ASSERT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kAccepted);
  for (int i = 0; i < kTrials; ++i)
    ASSERT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kReplayed);
  std::vector<uint8_t> next = payload();
  lab.predictor.vouch("OBJECT_TRAJECTORY", next);  // same clock: counter = last + 1
  EXPECT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", next), GuardVerdict::kAccepted);
  EXPECT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kReplayed);
}

// A counter 30 s behind or ahead of the reader is stale (a log played onto a live bus): at
// max_age it is accepted, 1 us beyond it refused; both ways.
TEST(DataAuth, StaleCountersAreRefusedBothWays) {
  Lab lab;
  std::vector<uint8_t> old = payload();
  lab.predictor.vouch("OBJECT_TRAJECTORY", old);
  EXPECT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", old, kT0 + 30'000'001), GuardVerdict::kStale);
  EXPECT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", old, kT0 + 30'000'000),
            GuardVerdict::kAccepted);
  std::vector<uint8_t> ahead = payload();
  lab.clock.at = kT0 + 60'000'000;
  lab.predictor.vouch("OBJECT_TRAJECTORY", ahead);
  EXPECT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", ahead, kT0 + 29'000'000), GuardVerdict::kStale);
}

// Two instances of one identity keep their own counters: interleaved, both are accepted.
TEST(DataAuth, InstancesOfOneIdentityKeepTheirOwnCounters) {
  Lab lab;
  ManualClock late;
  late.at = kT0 + 1000;
  DataGuard second(credentials_from_lab_key(lab.key, "sg-predictor"), {}, late, 77);
  for (int i = 0; i < 100; ++i) {
    std::vector<uint8_t> a = payload(), b = payload();
    second.vouch("OBJECT_TRAJECTORY", b);  // always ahead of the first
    lab.predictor.vouch("OBJECT_TRAJECTORY", a);
    ASSERT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", b), GuardVerdict::kAccepted);
    ASSERT_EQ(verdict(lab.grasp, "OBJECT_TRAJECTORY", a), GuardVerdict::kAccepted);
  }
  EXPECT_EQ(lab.grasp.streams(), 2u);
}

// The replay table stays bounded: the stream longest without an accepted message goes first.
TEST(DataAuth, StreamTableIsBounded) {
  Lab lab;
  DataGuardSettings small;
  small.max_streams = 8;
  DataGuard grasp(credentials_from_lab_key(lab.key, "sg-grasp"), small, lab.clock, 5);
  for (uint32_t i = 1; i <= 100; ++i) {
    DataGuard run(credentials_from_lab_key(lab.key, "sg-predictor"), {}, lab.clock, i);
    std::vector<uint8_t> m = payload();
    run.vouch("OBJECT_TRAJECTORY", m);
    ASSERT_EQ(verdict(grasp, "OBJECT_TRAJECTORY", m), GuardVerdict::kAccepted);
  }
  EXPECT_EQ(grasp.streams(), 8u);
}

// The pair key, the one-time key and the tag, computed independently with libsodium's one-shot
// BLAKE2b and Poly1305 over the bytes the header documents.
TEST(DataAuth, KeysAndTagsAreTheDocumentedBlake2b) {
  const LabKey lab = key_of(9);
  std::vector<uint8_t> label = {'s', 'g', '-', 'p', 'a', 'i', 'r', '-',
                                'v', '1', 1,   'a', 2,   'b', 'c'};
  std::array<uint8_t, 32> expected{};
  crypto_generichash(expected.data(), 32, label.data(), label.size(), lab.bytes().data(), 32);
  EXPECT_EQ(pair_key(lab, "a", "bc").bytes(), expected);
  EXPECT_NE(pair_key(lab, "bc", "a").bytes(), expected);

  const PairKey pair = pair_key(lab, "a", "bc");
  const VouchTrailer t{"s", 0x01020304, 0x05, {}};
  const std::vector<uint8_t> k_input = {'s', 'g', '-', 'o', 't', 'k', '-', 'v', '1',
                                        2,   'C', 'H', 1,   's', 1,   2,   3,   4,
                                        0,   0,   0,   0,   0,   0,   0,   5};
  std::array<uint8_t, 32> k{};
  crypto_generichash(k.data(), 32, k_input.data(), k_input.size(), pair.bytes().data(), 32);
  EXPECT_EQ(one_time_key(pair, "CH", t), k);
  const std::vector<uint8_t> body = {7, 8, 9};
  std::array<uint8_t, 16> tag{};
  crypto_onetimeauth(tag.data(), body.data(), body.size(), k.data());
  EXPECT_EQ(vouch_tag(pair, "CH", t, body.data(), body.size()), tag);
}

// The default rights: each reader of a channel holds a receive peer for each of its publishers,
// and a lab-key process vouches on PROCESS_STATUS to every identity.
TEST(DataAuth, DefaultRightsGiveEachProcessItsPeers) {
  const LabKey lab = key_of(4);
  const Credentials grasp = credentials_from_lab_key(lab, "sg-grasp");
  std::vector<std::string> believes;
  for (const Peer& p : grasp.receive)
    for (const std::string& c : p.channels)
      if (c != "PROCESS_STATUS") believes.push_back(p.name + " " + c);
  std::sort(believes.begin(), believes.end());
  EXPECT_EQ(believes, (std::vector<std::string>{
                          "sg-arm-driver ARM_STATUS", "sg-grasp-ctl GRASP_COMMAND",
                          "sg-predictor OBJECT_TRAJECTORY", "sg-vision OBJECT_POSITION"}));
  size_t status_readers = 0;
  for (const Peer& p : grasp.send)
    status_readers += std::count(p.channels.begin(), p.channels.end(), "PROCESS_STATUS");
  EXPECT_EQ(status_readers, known_identities().size());
  EXPECT_THROW(credentials_from_lab_key(lab, "no spaces"), std::invalid_argument);
}

}  // namespace
}  // namespace sg::auth
