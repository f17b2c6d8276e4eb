#include "sim/real_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace sg::sim {
namespace {

constexpr int kWidth = 640, kHeight = 480, kCycle = 720;
constexpr int kNoiseFields = 4, kNoiseMargin = 64;
const cv::Vec3d kBallAlbedo(0.10, 0.12, 0.80);  // BGR, the simulator's ball (camera_simulator)
const cv::Vec3d kClothColour(35, 42, 135);      // BGR, red-brown: inside the default ranges
const cv::Rect kCloth(470, 120, 160, 280);
const cv::Rect kBook(540, 30, 60, 36);  // a red book on the shelf: twice the ball's area

/// Where the ball is at frame k (a Lissajous figure over the left of the image).
RealSceneTruth ball_at(int k) {
  RealSceneTruth t;
  t.centre = {260 + 150 * std::sin(2 * M_PI * k / 241.0),
              240 + 120 * std::sin(2 * M_PI * k / 173.0 + 0.5)};
  t.radius = 22 + 6 * std::sin(2 * M_PI * k / 307.0);
  return t;
}

/// 0 to 1 over frames [a, b) of the cycle.
double ramp(int phase, int a, int b) {
  return std::clamp((phase - a) / static_cast<double>(b - a), 0.0, 1.0);
}

cv::Mat fit_to_frame(const cv::Mat& in) {
  cv::Mat out;
  cv::resize(in, out, {kWidth, kHeight}, 0, 0, cv::INTER_AREA);
  return out;
}

}  // namespace

std::string opencv_data_dir() {
  const char* env = std::getenv("SG_OPENCV_DATA");
  return env != nullptr && *env != '\0' ? env : "/usr/share/doc/opencv-doc/examples/data";
}

RealScene::RealScene(const RealSceneParams& p) : params_(p) {
  const std::string path = opencv_data_dir() + "/" + p.background;
  const bool is_video = path.size() > 4 && path.substr(path.size() - 4) == ".avi";
  if (!std::filesystem::exists(path)) {
    throw std::runtime_error("real scene: no " + path +
                             " (apt-get install opencv-doc, or set SG_OPENCV_DATA)");
  }
  if (is_video) {
    video_.open(path);
    video_frames_ = static_cast<int>(video_.get(cv::CAP_PROP_FRAME_COUNT));
    if (!video_.isOpened() || video_frames_ <= 0)
      throw std::runtime_error("real scene: cannot read the video " + path);
  } else {
    const cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
    if (img.empty()) throw std::runtime_error("real scene: cannot read the image " + path);
    photo_ = fit_to_frame(img);
  }
  texture_.create(kCloth.size(), CV_32F);
  cv::RNG weave(p.seed + 99);
  weave.fill(texture_, cv::RNG::UNIFORM, 0.85, 1.1);
  cv::GaussianBlur(texture_, texture_, {0, 0}, 1.5);
  for (int y = 0; y < texture_.rows; ++y) {  // folds: slow shading bands across the cloth
    for (int x = 0; x < texture_.cols; ++x)
      texture_.at<float>(y, x) *= static_cast<float>(0.85 + 0.15 * std::sin(x / 11.0 + y / 37.0));
  }
  make_noise_bank();
}

// Drawing 921,600 normal deviates a frame cost more than the rest of the frame: a few fields are
// drawn once, and frame k adds a window of one at an offset of its own.
void RealScene::make_noise_bank() {
  if (params_.noise_sigma <= 0) return;
  cv::RNG rng(params_.seed * 1000003ULL + 17);
  noise_.resize(kNoiseFields);
  for (cv::Mat& field : noise_) {
    field.create(kHeight + kNoiseMargin, kWidth + kNoiseMargin, CV_16SC3);
    rng.fill(field, cv::RNG::NORMAL, 0, params_.noise_sigma);
  }
}

void RealScene::background(int k, cv::Mat& out) {
  if (!photo_.empty()) {
    photo_.copyTo(out);
    return;
  }
  const int f = k % video_frames_;
  if (static_cast<int>(video_.get(cv::CAP_PROP_POS_FRAMES)) != f)
    video_.set(cv::CAP_PROP_POS_FRAMES, f);
  cv::Mat frame;
  if (!video_.read(frame) || frame.empty())
    throw std::runtime_error("real scene: frame " + std::to_string(f) +
                             " of the video is unreadable");
  out = fit_to_frame(frame);
}

void RealScene::draw_clutter(cv::Mat& image) const {
  if (params_.cloth) {
    for (int y = 0; y < kCloth.height; ++y) {
      for (int x = 0; x < kCloth.width; ++x) {
        const double s = texture_.at<float>(y, x);
        image.at<cv::Vec3b>(kCloth.y + y, kCloth.x + x) =
            cv::Vec3b(cv::saturate_cast<uint8_t>(kClothColour[0] * s),
                      cv::saturate_cast<uint8_t>(kClothColour[1] * s),
                      cv::saturate_cast<uint8_t>(kClothColour[2] * s));
      }
    }
  }
  if (params_.red_book) {
    image(kBook).setTo(cv::Scalar(30, 30, 170));
    image(cv::Rect(kBook.x, kBook.y + 16, kBook.width, 4)).setTo(cv::Scalar(40, 150, 200));
  }
}

void RealScene::draw_ball(const RealSceneTruth& t, cv::Mat& image, cv::Mat& coverage) const {
  coverage = cv::Mat::zeros(image.size(), CV_32F);
  const cv::Vec3d light = cv::normalize(cv::Vec3d(-0.35, -0.4, 0.85));
  const int x0 = std::max(0, static_cast<int>(t.centre.x - t.radius) - 1);
  const int x1 = std::min(kWidth - 1, static_cast<int>(t.centre.x + t.radius) + 1);
  const int y0 = std::max(0, static_cast<int>(t.centre.y - t.radius) - 1);
  const int y1 = std::min(kHeight - 1, static_cast<int>(t.centre.y + t.radius) + 1);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      int inside = 0;
      cv::Vec3d colour(0, 0, 0);
      for (int s = 0; s < 16; ++s) {  // 4x4 samples per pixel
        const double dx = (x - 0.375 + 0.25 * (s % 4) - t.centre.x) / t.radius;
        const double dy = (y - 0.375 + 0.25 * (s / 4) - t.centre.y) / t.radius;
        const double rr = dx * dx + dy * dy;
        if (rr > 1) continue;
        ++inside;
        const cv::Vec3d n(dx, dy, -std::sqrt(1 - rr));  // toward the camera is -z
        const double lambert = std::max(0.0, n.dot(cv::Vec3d(light[0], light[1], -light[2])));
        colour += kBallAlbedo * (0.45 + 0.6 * lambert) * 255.0;
      }
      if (inside == 0) continue;
      const double c = inside / 16.0;
      coverage.at<float>(y, x) = static_cast<float>(c);
      cv::Vec3b& px = image.at<cv::Vec3b>(y, x);
      for (int ch = 0; ch < 3; ++ch)
        px[ch] = cv::saturate_cast<uint8_t>(colour[ch] / inside * c + px[ch] * (1 - c));
    }
  }
}

double RealScene::occlude(int phase, const RealSceneTruth& t, cv::Mat& image,
                          cv::Mat& coverage) const {
  const double full = cv::sum(coverage)[0];
  cv::Mat hidden = cv::Mat::zeros(image.size(), CV_8U);
  if (phase >= 300 && phase < 510) {  // the panel: covers x >= edge
    const double s = phase < 450 ? ramp(phase, 300, 360) : 1 - ramp(phase, 450, 510);
    const int edge = static_cast<int>(std::lround(t.centre.x + t.radius * (1 - 2.2 * s)));
    if (edge < kWidth)
      hidden(cv::Rect(std::max(0, edge), 0, kWidth - std::max(0, edge), kHeight)) = 255;
  } else if (phase >= 510 && phase < 600) {  // two fingers closing from the sides, from above
    const double s = ramp(phase, 510, 560);
    const double gap = t.radius * (1.3 - 0.75 * s), width = 0.6 * t.radius;
    const int bottom = static_cast<int>(t.centre.y + 0.8 * t.radius);
    for (double side : {-1.0, 1.0}) {
      const double inner = t.centre.x + side * gap;
      const double a = side < 0 ? inner - width : inner, b = side < 0 ? inner : inner + width;
      const cv::Rect r(static_cast<int>(std::lround(a)), 0, static_cast<int>(std::lround(b - a)),
                       bottom);
      hidden(r & cv::Rect(0, 0, kWidth, kHeight)) = 255;
    }
  }
  image.setTo(cv::Scalar(60, 66, 72), hidden);  // grey panel, dark grey fingers alike
  coverage.setTo(0, hidden);
  return full > 0 ? cv::sum(coverage)[0] / full : 0;
}

void RealScene::degrade(int k, cv::Mat& image) {
  if (params_.lighting) {
    const double gain = 0.95 + 0.3 * std::sin(2 * M_PI * k / 400.0);
    const double warm = 0.08 * std::sin(2 * M_PI * k / 555.0);
    cv::multiply(image, cv::Scalar(gain * (1 - warm), gain, gain * (1 + warm)), image);
  }
  if (!noise_.empty()) {
    const uint64_t h = (params_.seed + 1) * 0x9E3779B97F4A7C15ULL * static_cast<uint64_t>(k + 1);
    const cv::Rect window(static_cast<int>((h >> 20) % kNoiseMargin),
                          static_cast<int>((h >> 40) % kNoiseMargin), kWidth, kHeight);
    cv::Mat wide;
    image.convertTo(wide, CV_16SC3);
    wide += noise_[static_cast<size_t>(k) % noise_.size()](window);
    wide.convertTo(image, CV_8UC3);
  }
  if (params_.jpeg_quality > 0) {
    std::vector<uint8_t> jpeg;
    cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, params_.jpeg_quality});
    image = cv::imdecode(jpeg, cv::IMREAD_COLOR);
  }
}

void RealScene::render(int k, cv::Mat& bgr, RealSceneTruth& truth) {
  background(k, bgr);
  draw_clutter(bgr);
  truth = ball_at(k);
  const int phase = params_.occlusion ? k % kCycle : 0;
  truth.in_view = phase < 600;
  truth.visible = 0;
  if (truth.in_view) {
    cv::Mat coverage;
    draw_ball(truth, bgr, coverage);
    truth.visible = occlude(phase, truth, bgr, coverage);
  }
  degrade(k, bgr);
}

std::vector<RealSceneParams> standard_real_scenes(int frames) {
  std::vector<RealSceneParams> s(3);
  s[0].name = "home+cloth", s[0].background = "home.jpg";
  s[1].name = "fruits", s[1].background = "fruits.jpg", s[1].cloth = false;
  s[2].name = "vtest+cloth", s[2].background = "vtest.avi";
  for (size_t i = 0; i < s.size(); ++i) s[i].frames = frames, s[i].seed = 1 + i;
  return s;
}

}  // namespace sg::sim
