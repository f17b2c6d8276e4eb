#include "vision/viewer_canvas.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace sg::vision {
namespace {

const cv::Scalar kCross(0, 255, 0), kAxes(255, 128, 0), kBox(255, 255, 0), kPath(255, 0, 255),
    kText(255, 255, 255), kFit(0, 200, 255);

cv::Point px(double x, double y, int dx) { return {cvRound(x) + dx, cvRound(y)}; }

void draw_blob(cv::Mat& canvas, const stereograsp::blob_t& b, int dx) {
  const int* w = b.search_window;
  cv::rectangle(canvas, cv::Rect(w[0] + dx, w[1], w[2], w[3]), kWindowColour, 2);
  if (!b.found) return;
  const cv::Point c = px(b.centroid[0], b.centroid[1], dx);
  cv::drawMarker(canvas, c, kCross, cv::MARKER_CROSS, 16, 2);
  cv::line(canvas, px(b.major_axis_ends[0][0], b.major_axis_ends[0][1], dx),
           px(b.major_axis_ends[1][0], b.major_axis_ends[1][1], dx), kAxes, 1);
  cv::line(canvas, px(b.minor_axis_ends[0][0], b.minor_axis_ends[0][1], dx),
           px(b.minor_axis_ends[1][0], b.minor_axis_ends[1][1], dx), kAxes, 1);
  cv::rectangle(canvas, px(b.bounding_box[0], b.bounding_box[1], dx),
                px(b.bounding_box[2], b.bounding_box[3], dx), kBox, 1);
  // The ball's outline (and centre) as fitted when part of it is hidden; a value off the canvas,
  // as a forged message may carry, is not drawn.
  const double limit = 4.0 * canvas.cols;
  if (std::isfinite(b.fit_support) && std::isfinite(b.centre[0]) && std::isfinite(b.centre[1]) &&
      std::abs(b.centre[0]) < limit && std::abs(b.centre[1]) < limit && b.radius > 0 &&
      b.radius < limit) {
    const cv::Point centre = px(b.centre[0], b.centre[1], dx);
    cv::circle(canvas, centre, cvRound(b.radius), kFit, 1, cv::LINE_AA);
    cv::drawMarker(canvas, centre, kFit, cv::MARKER_TILTED_CROSS, 10, 1);
  }
}

void draw_trajectory(cv::Mat& canvas, const stereograsp::trajectory_t& t, const CameraModel& cam,
                     int dx) {
  for (const auto& p : t.position) {
    if (p.size() != 3) continue;
    if (auto pixel = cam.project({p[0], p[1], p[2]})) {
      cv::circle(canvas, px(pixel->x(), pixel->y(), dx), 3, kPath, 1);
    }
  }
}

}  // namespace

void draw_view(const ViewerState& s, cv::Mat& canvas) {
  const cv::Size size = s.images[0].empty() ? cv::Size(640, 480) : s.images[0].size();
  canvas.create(size.height + 40, size.width * 2, CV_8UC3);
  canvas.setTo(cv::Scalar(30, 30, 30));
  for (int i = 0; i < 2; ++i) {
    const cv::Mat& image = s.images[static_cast<size_t>(i)];
    const int dx = i * size.width;
    if (!image.empty() && image.size() == size)
      image.copyTo(canvas(cv::Rect(dx, 0, size.width, size.height)));
    if (s.blobs[static_cast<size_t>(i)]) draw_blob(canvas, *s.blobs[static_cast<size_t>(i)], dx);
    if (s.trajectory && s.calibration) {
      draw_trajectory(canvas, *s.trajectory, i == 0 ? s.calibration->left : s.calibration->right,
                      dx);
    }
  }
  char line[256];
  if (s.position && s.position->visible) {
    std::snprintf(line, sizeof line, "X %+.3f  Y %+.3f  Z %+.3f m", s.position->position[0],
                  s.position->position[1], s.position->position[2]);
  } else {
    std::snprintf(line, sizeof line,
                  s.position ? "ball not seen by both cameras" : "no 3D position");
  }
  std::string text = line;
  if (s.grasp) text += "   grasp q" + std::to_string(s.grasp->state);
  std::snprintf(line, sizeof line, "   %.1f fps", s.frame_rate);
  text += line;
  cv::putText(canvas, text, {10, size.height + 27}, cv::FONT_HERSHEY_SIMPLEX, 0.6, kText, 1,
              cv::LINE_AA);
}

}  // namespace sg::vision
