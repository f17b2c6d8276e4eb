#include "predictor/position_gate.hpp"

#include <cstdio>
#include <numeric>

namespace sg::predictor {
namespace {

std::string xyz(const Eigen::Vector3d& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.4g, %.4g, %.4g)", p.x(), p.y(), p.z());
  return text;
}

}  // namespace

const char* to_string(PositionRefusal reason) {
  switch (reason) {
    case PositionRefusal::kNonFinite:
      return "non-finite";
    case PositionRefusal::kOutsideWorkspace:
      return "outside the workspace";
    case PositionRefusal::kTimeFarFromNow:
      return "time far from now";
  }
  return "?";
}

std::optional<PositionRefusal> PositionGate::check(const Measurement& m, int64_t now) {
  const int64_t limit = params_.max_time_offset_us;
  // |utime - now| > limit, without overflow for any int64 pair.
  if (limit > 0 && (m.utime > now ? static_cast<uint64_t>(m.utime) - static_cast<uint64_t>(now)
                                  : static_cast<uint64_t>(now) - static_cast<uint64_t>(m.utime)) >
                       static_cast<uint64_t>(limit)) {
    return refuse(
        PositionRefusal::kTimeFarFromNow,
        "capture time " + std::to_string(m.utime) + " us is " +
            std::to_string((static_cast<double>(m.utime) - static_cast<double>(now)) * 1e-6) +
            " s from the receiver's clock (at most " +
            std::to_string(static_cast<double>(limit) * 1e-6) + " s)");
  }
  if (!m.visible) return std::nullopt;
  if (!m.position.allFinite()) {
    return refuse(PositionRefusal::kNonFinite, "position " + xyz(m.position) + " is not finite");
  }
  const Eigen::Vector3d lo = params_.box_min.array() - params_.margin;
  const Eigen::Vector3d hi = params_.box_max.array() + params_.margin;
  if (!((m.position.array() >= lo.array()).all() && (m.position.array() <= hi.array()).all())) {
    return refuse(PositionRefusal::kOutsideWorkspace, "position " + xyz(m.position) +
                                                          " m outside the workspace " + xyz(lo) +
                                                          " .. " + xyz(hi) + " m");
  }
  return std::nullopt;
}

uint64_t PositionGate::refused() const {
  return std::accumulate(counts_.begin(), counts_.end(), uint64_t{0});
}

std::string PositionGate::counts_text() const {
  std::string text;
  for (int i = 0; i < kPositionRefusals; ++i) {
    text += (i ? ", " : "") + std::string(to_string(static_cast<PositionRefusal>(i))) + " " +
            std::to_string(counts_[static_cast<size_t>(i)]);
  }
  return text;
}

std::optional<PositionRefusal> PositionGate::refuse(PositionRefusal reason, std::string line) {
  ++counts_[static_cast<size_t>(reason)];
  last_ = std::move(line);
  return reason;
}

}  // namespace sg::predictor
