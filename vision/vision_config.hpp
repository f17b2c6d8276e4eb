#pragma once

#include "common/config.hpp"
#include "vision/blob_tracker.hpp"

namespace sg::vision {

/// Reads the tracker's parameters from the `vision` section (colour ranges, window, minimum
/// area); every key optional. Throws ConfigError naming a bad key.
BlobTracker::Params load_tracker_params(const Config& config);

}  // namespace sg::vision
