#pragma once

/// For test harnesses that stand in for one of the lab's processes on a guarded bus: the
/// product's auth::VouchingPublisher as `identity` under a lab key (the process tests'
/// $SG_LAB_KEY by default): it vouches for what the harness publishes and believes whatever
/// arrives. The product's own processes use auth::DataGuard on both sides.
///
///     sg::Bus bus(url);
///     bus.set_guard(sg::test::vouching_as("sg-vision"));   // the predictor believes these
///     bus.publish("OBJECT_POSITION", p);

#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>

#include "auth/data_auth.hpp"
#include "common/bus.hpp"
#include "common/vouch_trailer.hpp"
#include "stereograsp/process_status_t.hpp"

namespace sg::test {

using HarnessGuard = auth::VouchingPublisher;

/// The lab key of the process tests ($SG_LAB_KEY), or `path`.
inline auth::LabKey test_lab_key(const std::string& path = "") {
  if (!path.empty()) return auth::LabKey::load(path);
  const char* env = std::getenv("SG_LAB_KEY");
  if (env == nullptr || *env == '\0')
    throw std::runtime_error("SG_LAB_KEY is not set (ctest sets it for process tests)");
  return auth::LabKey::load(env);
}

inline std::shared_ptr<HarnessGuard> vouching_as(const std::string& identity,
                                                 const std::string& key_path = "") {
  return std::make_shared<HarnessGuard>(
      auth::credentials_from_lab_key(test_lab_key(key_path), identity));
}

/// The refusals a PROCESS_STATUS reports on `channel` with `verdict` (any sender).
inline int64_t unvouched(const stereograsp::process_status_t& s, const std::string& channel,
                         const std::string& verdict) {
  int64_t n = 0;
  for (int i = 0; i < s.num_unvouched; ++i)
    if (s.unvouched_channel[i] == channel && s.unvouched_verdict[i] == verdict)
      n += s.unvouched_count[i];
  return n;
}

}  // namespace sg::test
