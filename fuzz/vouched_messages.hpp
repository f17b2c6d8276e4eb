#pragma once

/// The messages vouch_check_fuzz knows to be vouched for, and its input format, shared with
/// sg_fuzz_seeds (fuzz/seeds.cpp) so the committed seeds and the target agree to the byte.
///
/// An input is up to kMaxRecords records, each
///     selector (1 byte) || length (2 bytes, big-endian) || that many bytes (fewer at the end),
/// the selector picking the channel the bytes arrive on (bits 0-1: kVouchChannels) and the
/// reader's clock (bits 2-7: now = kNow + (s - 32) * 2 s, so 32 is kNow itself). The reader is
/// sg-grasp under the lab rights (auth::default_channel_rights) and the fuzzer's fixed lab key.

#include <array>
#include <string>
#include <vector>

#include "auth/data_auth.hpp"
#include "fuzz/signed_commands.hpp"

namespace sg::fuzz {

inline const std::array<std::string, 4> kVouchChannels = {"OBJECT_TRAJECTORY", "ARM_STATUS",
                                                          "OBJECT_POSITION", "PROCESS_STATUS"};

/// One message as it travels: its channel and its bytes, trailer included.
struct VouchedMessage {
  int channel = 0;  ///< index into kVouchChannels
  std::vector<uint8_t> bytes;
};

/// Vouched for with fuzz_key() at kSignedAt: two forecasts from sg-predictor (instance 1,
/// counters kSignedAt and kSignedAt + 1) and an ARM_STATUS from sg-arm-driver (instance 2).
/// These, on their channel, are the only inputs sg-grasp's guard may ever accept.
inline std::vector<VouchedMessage> vouched_messages() {
  FixedClock clock;
  auth::DataGuard predictor(auth::credentials_from_lab_key(fuzz_key(), "sg-predictor"), {}, clock,
                            1);
  auth::DataGuard driver(auth::credentials_from_lab_key(fuzz_key(), "sg-arm-driver"), {}, clock, 2);
  std::vector<VouchedMessage> out;
  for (int n : {16, 8}) {
    stereograsp::trajectory_t t{};
    t.utime = t.source_utime = kSignedAt;
    t.num_points = n;
    t.position.assign(static_cast<std::size_t>(n), {0.45, 0.0, 0.1});
    t.position_sigma.assign(static_cast<std::size_t>(n), {0.001, 0.001, 0.001});
    VouchedMessage m{0, encode_message(t)};
    predictor.vouch(kVouchChannels[0], m.bytes);
    out.push_back(m);
  }
  stereograsp::arm_status_t s{};
  s.utime = kSignedAt;
  VouchedMessage m{1, encode_message(s)};
  driver.vouch(kVouchChannels[1], m.bytes);
  out.push_back(m);
  return out;
}

/// The first forecast vouched for by sg-vision (not allowed on OBJECT_TRAJECTORY) and by
/// sg-predictor under other_key() (a bad tag).
inline std::vector<VouchedMessage> not_allowed_and_wrong_key() {
  FixedClock clock;
  std::vector<VouchedMessage> out;
  for (const auto& [who, key] :
       {std::pair{"sg-vision", fuzz_key()}, std::pair{"sg-predictor", other_key()}}) {
    auth::DataGuard g(auth::credentials_from_lab_key(key, who), {}, clock, 3);
    VouchedMessage m = vouched_messages()[0];
    m.bytes.resize(vouched_payload_size(m.bytes.data(), m.bytes.size()));
    g.vouch(kVouchChannels[0], m.bytes);
    out.push_back(m);
  }
  return out;
}

inline void append_vouch_record(std::vector<uint8_t>& input, const VouchedMessage& m,
                                int clock_step = 32) {
  input.push_back(static_cast<uint8_t>(m.channel | (clock_step << 2)));
  input.push_back(static_cast<uint8_t>(m.bytes.size() >> 8));
  input.push_back(static_cast<uint8_t>(m.bytes.size()));
  input.insert(input.end(), m.bytes.begin(), m.bytes.end());
}

}  // namespace sg::fuzz
