// sg-viewer's session: a stereo frame is drawn once its images and blobs are in, and recorded.

#include "vision/viewer_session.hpp"

#include <gtest/gtest.h>

#include "tests/support/subprocess.hpp"

namespace sg::vision {
namespace {

stereograsp::blob_t blob_at(int64_t utime) {
  stereograsp::blob_t b{};
  b.utime = utime;
  return b;
}

// A frame waits for both blobs, is drawn once, shown, and written with its utime to the index.
TEST(ViewerSession, DrawsACompleteFrameAndRecordsIt) {
  const std::string video = test::make_temp_dir() + "/view.avi";
  int shown = 0;
  ViewerSession session({video, 30, true}, nullptr, [&](const cv::Mat& c) {
    EXPECT_FALSE(c.empty());
    ++shown;
  });
  const cv::Mat image(240, 320, CV_8UC3, cv::Scalar(40, 40, 40));
  session.on_image(0, 1000, image);
  session.on_image(1, 1000, image);
  session.on_blob(0, blob_at(1000));
  EXPECT_EQ(session.drawn(), 0) << "the right blob is missing";
  session.on_blob(1, blob_at(1000));
  EXPECT_EQ(session.drawn(), 1);
  session.on_blob(1, blob_at(1000));  // a duplicate: the frame is gone
  EXPECT_EQ(session.drawn(), 1);
  EXPECT_EQ(shown, 1);
  EXPECT_EQ(test::read_text(video + ".csv"), "video_frame,utime\n0,1000\n");
}

// Without waiting for blobs, the images alone are drawn.
TEST(ViewerSession, DrawsImagesAloneWhenNotWaiting) {
  ViewerSession session({"", 30, false}, nullptr);
  const cv::Mat image(120, 160, CV_8UC3, cv::Scalar(0, 0, 0));
  session.on_image(0, 5, image);
  session.on_image(1, 5, image);
  EXPECT_EQ(session.drawn(), 1);
}

}  // namespace
}  // namespace sg::vision
