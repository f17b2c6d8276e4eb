// Drives the stereo calibration loader (vision/calibration_file.hpp, read_calibration: what
// sg-vision, sg-viewer and sg-calibrate read camera matrices from) with any file: the input is
// written to an in-memory file and read through OpenCV's FileStorage as the programs do.
// Asserts, beyond not crashing:
//  - the only error is CalibrationError (naming the file);
//  - a file that loads holds what the format promises: positive image size, finite K,
//    distortion, R and t, R a rotation, P = K [R|t];
//  - a loaded calibration written again (write_calibration) and read back is the same to the
//    last bit (FileStorage prints doubles with %.17g), with the same source (and date, when it had one).

#include <opencv2/core/utility.hpp>

#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.hpp"
#include "vision/calibration_file.hpp"

namespace vision = sg::vision;

namespace {

void check_camera(const vision::CameraModel& cam, const char* name) {
  SG_FUZZ_CHECK(cam.width() > 0 && cam.height() > 0, "%s: image size", name);
  SG_FUZZ_CHECK(cam.K().allFinite() && cam.R().allFinite() && cam.t().allFinite(),
                "%s: not finite", name);
  SG_FUZZ_CHECK((cam.R().transpose() * cam.R()).isApprox(Eigen::Matrix3d::Identity(), 1e-6),
                "%s: R is not a rotation", name);
}

bool same(const vision::CameraModel& a, const vision::CameraModel& b) {
  const auto& da = a.distortion();
  const auto& db = b.distortion();
  return a.width() == b.width() && a.height() == b.height() && a.K() == b.K() && a.R() == b.R() &&
         a.t() == b.t() && da.k1 == db.k1 && da.k2 == db.k2 && da.p1 == db.p1 &&
         da.p2 == db.p2 && da.k3 == db.k3;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static sg::fuzz::MemoryFile file;
  static const std::string again = [] {
    cv::setNumThreads(1);
    return std::string("/dev/shm/sg-calibration-fuzz-") + std::to_string(getpid()) + ".yaml";
  }();
  const std::string& path = file.write(data, size);
  vision::StereoCalibration c;
  try {
    c = vision::read_calibration(path);
  } catch (const vision::CalibrationError& e) {
    SG_FUZZ_CHECK(std::string(e.what()).starts_with(path), "error without the file: %s",
                  e.what());
    return 0;
  }
  check_camera(c.left, "left");
  check_camera(c.right, "right");
  vision::write_calibration(again, c);
  const vision::StereoCalibration back = vision::read_calibration(again);
  std::remove(again.c_str());
  SG_FUZZ_CHECK(same(c.left, back.left) && same(c.right, back.right), "cameras differ");
  SG_FUZZ_CHECK(c.rms_left == back.rms_left && c.rms_right == back.rms_right, "rms differs");
  SG_FUZZ_CHECK(c.source == back.source, "source '%s' read back as '%s'", c.source.c_str(),
                back.source.c_str());
  SG_FUZZ_CHECK(c.date.empty() || c.date == back.date, "date '%s' read back as '%s'",
                c.date.c_str(), back.date.c_str());
  return 0;
}
