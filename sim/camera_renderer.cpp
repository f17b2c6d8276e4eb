#include "sim/camera_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>

#include "sim/box_from_eye.hpp"

namespace sg::sim {
namespace {

constexpr int kSuper = 4;        // edge pixels: kSuper x kSuper rays
constexpr int kNoiseFrames = 8;  // sensor-noise frames, reused in turn

cv::Vec3b to_pixel(const Eigen::Vector3d& bgr) {
  return {cv::saturate_cast<uint8_t>(bgr.x()), cv::saturate_cast<uint8_t>(bgr.y()),
          cv::saturate_cast<uint8_t>(bgr.z())};
}

Eigen::Vector3d from_pixel(const cv::Vec3b& p) {
  return {double(p[0]), double(p[1]), double(p[2])};
}

/// Bilinear blend of the rays through a pixel's four corners, at (u, v) in [0, 1]^2.
Eigen::Vector3d blend(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Eigen::Vector3d& d, double u, double v) {
  // Component by component: the same arithmetic as Eigen's expression, without its temporaries
  // (this runs for every ray the renderer casts).
  double r[3];
  for (int k = 0; k < 3; ++k) {
    const double ab = (1 - u) * a[k] + u * b[k], cd = (1 - u) * c[k] + u * d[k];
    r[k] = (1 - v) * ab + v * cd;
  }
  const double norm = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  return norm > 0 ? Eigen::Vector3d(r[0] / norm, r[1] / norm, r[2] / norm)
                  : Eigen::Vector3d(r[0], r[1], r[2]);
}

/// The corners of the cube around a sphere: their screen box holds the sphere's image.
std::vector<Eigen::Vector3d> sphere_cube(const Eigen::Vector3d& centre, double radius) {
  std::vector<Eigen::Vector3d> cube;
  for (int i = 0; i < 8; ++i) {
    cube.push_back(centre +
                   radius * Eigen::Vector3d(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  }
  return cube;
}

// ---- the static lab -------------------------------------------------------------------------

const Eigen::Vector3d kRedAlbedo{0.10, 0.12, 0.80};

struct Sticker {
  Eigen::Vector3d centre;
  double radius;
};

Eigen::Vector3d wood(double x, double y) {
  const double grain =
      0.5 + 0.5 * std::sin(90 * y + 3 * std::sin(5 * x) + std::sin(17 * x + 2 * y));
  const double plank = std::fmod(std::abs(y) + 10, 0.18) < 0.003 ? 0.6 : 1.0;
  return Eigen::Vector3d(0.26, 0.44, 0.62) * (0.9 + 0.1 * grain) * plank;
}

Eigen::Vector3d wall(double y, double z) {
  if (y > -0.55 && y < -0.15 && z > 0.35 && z < 0.75) {  // a poster with stripes
    return std::fmod(z * 20 + 10, 2.0) < 1.0 ? Eigen::Vector3d(0.70, 0.45, 0.20)
                                             : Eigen::Vector3d(0.35, 0.65, 0.30);
  }
  const bool joint = std::fmod(std::abs(y) + 10, 0.25) < 0.006 || std::fmod(z + 10, 0.25) < 0.006;
  return Eigen::Vector3d(0.76, 0.78, 0.80) * (joint ? 0.75 : 1.0);
}

/// What the background shows besides the table and the wall: the robot's base and the stickers.
struct StaticLab {
  double wall_x = 0.0;
  Box robot_base;
  std::vector<Sticker> stickers;
};

/// Red stickers of 8-14 mm radius, drawn from the seed: even ones on the table (away from the
/// ball's usual path around (0.45, 0)), odd ones on the wall.
std::vector<Sticker> place_stickers(const StaticSceneParams& params) {
  std::mt19937_64 rng(params.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Sticker> stickers;
  for (int i = 0; i < params.distractors; ++i) {
    const double radius = 0.008 + 0.006 * unit(rng);
    if (i % 2 == 0) {  // on the table, away from the ball's usual path around (0.45, 0)
      const double angle = 2 * M_PI * unit(rng), distance = 0.32 + 0.12 * unit(rng);
      stickers.push_back(
          {{0.45 + distance * std::cos(angle), distance * std::sin(angle), 0.0}, radius});
    } else {  // on the wall
      stickers.push_back({{params.wall_x, -0.6 + 1.2 * unit(rng), 0.1 + 0.5 * unit(rng)}, radius});
    }
  }
  return stickers;
}

/// The static lab of `params`: the wall's place, a grey 0.18 x 0.18 x 0.30 m robot base at the
/// origin, and the stickers.
StaticLab make_static_lab(const StaticSceneParams& params) {
  StaticLab lab;
  lab.wall_x = params.wall_x;
  lab.stickers = place_stickers(params);
  lab.robot_base.pose.translation() = Eigen::Vector3d(0, 0, 0.15);
  lab.robot_base.half_size = {0.09, 0.09, 0.15};
  lab.robot_base.material.albedo = {0.40, 0.40, 0.42};
  return lab;
}

/// Colour (BGR, 0-255) of the static lab along the ray from `eye` along `dir`: the nearest of the
/// table (Z = 0), the wall and the robot's base, a sticker where one lies, dark grey where the ray
/// hits nothing; lit by an ambient plus a diffuse term.
Eigen::Vector3d lab_colour(const StaticLab& lab, const Eigen::Vector3d& eye,
                           const Eigen::Vector3d& to_light, const Eigen::Vector3d& dir) {
  const Ray ray{eye, dir};
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d albedo(0.14, 0.14, 0.14), normal(0, 0, 1);
  if (dir.z() < 0) {
    const double t = -eye.z() / dir.z();
    const Eigen::Vector3d p = eye + t * dir;
    if (p.x() > lab.wall_x && p.x() < 4.0 && std::abs(p.y()) < 4.0) {
      best = t, albedo = wood(p.x(), p.y()), normal = {0, 0, 1};
    }
  }
  if (dir.x() < 0) {
    const double t = (lab.wall_x - eye.x()) / dir.x();
    const Eigen::Vector3d p = eye + t * dir;
    if (t < best && p.z() > 0) best = t, albedo = wall(p.y(), p.z()), normal = {1, 0, 0};
  }
  if (auto t = lab.robot_base.intersect(ray); t && *t < best) {
    best = *t;
    albedo = lab.robot_base.material.albedo;
    normal = lab.robot_base.normal_at(eye + *t * dir);
  }
  if (std::isfinite(best)) {
    const Eigen::Vector3d p = eye + best * dir;
    for (const Sticker& s : lab.stickers) {
      if ((p - s.centre).norm() < s.radius) albedo = kRedAlbedo;
    }
  }
  return albedo * (0.55 + 0.45 * std::max(0.0, normal.dot(to_light))) * 255.0;
}

/// Merges screen regions that overlap, until none do; a merged region holds the ball if either
/// did. Each pixel is then ray-cast once.
void merge_overlapping(std::vector<std::pair<cv::Rect, bool>>& regions) {
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t i = 0; i < regions.size() && !merged; ++i) {
      for (size_t j = i + 1; j < regions.size() && !merged; ++j) {
        if ((regions[i].first & regions[j].first).empty()) continue;
        regions[i] = {regions[i].first | regions[j].first, regions[i].second || regions[j].second};
        regions.erase(regions.begin() + static_cast<std::ptrdiff_t>(j));
        merged = true;
      }
    }
  }
}

}  // namespace

struct CameraRenderer::Objects {
  Sphere ball;
  bool has_ball = false;
  const std::vector<Box>* boxes = nullptr;
  /// The boxes as seen from the eye every ray starts at (prepare()).
  std::vector<BoxFromEye> from_eye;

  /// Call once `boxes` is set: every ray nearest() traces then starts at `eye`.
  void prepare(const Eigen::Vector3d& eye, const Eigen::Vector3d& to_light) {
    from_eye.clear();
    for (size_t i = 0; boxes != nullptr && i < boxes->size(); ++i) {
      from_eye.emplace_back((*boxes)[i], eye);
      from_eye.back().shade_faces((*boxes)[i].material, to_light);
    }
  }
  /// Screen boxes of the ball ([0]) and of each box ([1..]); a ray through a point outside an
  /// object's screen box cannot hit it, so it is not tested.
  std::vector<cv::Rect> screen;

  bool may_hit(size_t object, const cv::Point2f& at) const {
    const cv::Rect& r = screen[object];
    return at.x >= r.x && at.y >= r.y && at.x <= r.x + r.width && at.y <= r.y + r.height;
  }

  /// The first object `ray` hits; the ray starts at the eye prepare() was given (every ray the
  /// renderer casts starts at the camera centre).
  Hit nearest(const Ray& ray, const cv::Point2f& at) const {
    Hit hit;
    hit.distance = std::numeric_limits<double>::infinity();
    if (has_ball && may_hit(0, at)) {
      if (auto t = ball.intersect(ray)) hit = {0, *t};
    }
    const double d[3] = {ray.direction.x(), ray.direction.y(), ray.direction.z()};
    for (size_t i = 0; i < from_eye.size(); ++i) {
      if (!may_hit(i + 1, at)) continue;
      int face = -1;
      if (const double t = from_eye[i].intersect(d, &face); t < hit.distance) {
        hit = {static_cast<int>(i) + 1, t, face};
      }
    }
    return hit;
  }

  Eigen::Vector3d colour(const Hit& hit, const Ray& ray, const Eigen::Vector3d& to_light) const {
    const size_t i = static_cast<size_t>(hit.object - 1);
    if (hit.object > 0 && i < from_eye.size() && from_eye[i].flat && hit.face >= 0) {
      return from_eye[i].face_colour[hit.face];
    }
    const Eigen::Vector3d p = ray.origin + hit.distance * ray.direction;
    if (hit.object == 0) return shade(ball.material, ball.normal_at(p), ray.direction, to_light);
    const Box& box = (*boxes)[i];
    return shade(box.material, box.normal_at(p), ray.direction, to_light);
  }
};

CameraRenderer::CameraRenderer(const vision::CameraModel& camera, const StaticSceneParams& scene,
                               double noise_sigma)
    : camera_(camera), eye_(camera.centre()), to_light_(scene.to_light.normalized()) {
  const int w = camera.width(), h = camera.height();
  corner_rays_.resize(static_cast<size_t>(w + 1) * (h + 1));
  const Eigen::Matrix3d camera_to_world = camera.R().transpose();
  for (int y = 0; y <= h; ++y) {
    for (int x = 0; x <= w; ++x) {  // pixel centres are integers, so corners are at -0.5
      corner_rays_[static_cast<size_t>(y) * (w + 1) + x] =
          camera_to_world * camera.ray_camera({x - 0.5, y - 0.5});
    }
  }
  render_background(scene);
  make_noise(noise_sigma, scene.seed * 2654435761u + static_cast<uint64_t>(w));
}

void CameraRenderer::render_background(const StaticSceneParams& params) {
  const StaticLab lab = make_static_lab(params);
  const int w = camera_.width(), h = camera_.height();
  background_.create(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {  // 2 x 2 rays a pixel
      const auto &a = corner_ray(x, y), &b = corner_ray(x + 1, y), &c = corner_ray(x, y + 1),
                 &d = corner_ray(x + 1, y + 1);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (double v : {0.25, 0.75}) {
        for (double u : {0.25, 0.75})
          sum += lab_colour(lab, eye_, to_light_, blend(a, b, c, d, u, v));
      }
      background_.at<cv::Vec3b>(y, x) = to_pixel(sum / 4);
    }
  }
}

void CameraRenderer::make_noise(double sigma, uint64_t seed) {
  cv::RNG rng(seed);
  for (int i = 0; i < kNoiseFrames; ++i) {
    cv::Mat noise(background_.size(), CV_16SC3);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, std::max(sigma, 0.0));
    cv::Mat up, down;
    cv::max(noise, 0, up);
    cv::max(-noise, 0, down);
    up.convertTo(up, CV_8UC3);
    down.convertTo(down, CV_8UC3);
    noise_up_.push_back(up);
    noise_down_.push_back(down);
  }
}

std::optional<cv::Rect> CameraRenderer::screen_box(
    const std::vector<Eigen::Vector3d>& points) const {
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (const Eigen::Vector3d& p : points) {
    const auto pixel = camera_.project(p);
    if (!pixel) return std::nullopt;  // straddles or is behind the camera: not drawn
    x0 = std::min(x0, pixel->x()), y0 = std::min(y0, pixel->y());
    x1 = std::max(x1, pixel->x()), y1 = std::max(y1, pixel->y());
  }
  const double margin = camera_.distortion().is_zero() ? 2.0 : 2.0 + 0.05 * (x1 - x0);
  const cv::Rect box(cv::Point(static_cast<int>(std::floor(x0 - margin)),
                               static_cast<int>(std::floor(y0 - margin))),
                     cv::Point(static_cast<int>(std::ceil(x1 + margin)),
                               static_cast<int>(std::ceil(y1 + margin))));
  const cv::Rect clipped = box & cv::Rect(0, 0, camera_.width(), camera_.height());
  if (clipped.empty()) return std::nullopt;
  return clipped;
}

double CameraRenderer::render_region(const Objects& objects, const cv::Rect& region, cv::Mat& image,
                                     cv::Mat* ball_coverage) const {
  const int rw = region.width, rh = region.height;
  std::vector<int> ids(static_cast<size_t>(rw + 1) * (rh + 1));
  for (int y = 0; y <= rh; ++y) {
    for (int x = 0; x <= rw; ++x) {
      const cv::Point2f at(static_cast<float>(region.x + x), static_cast<float>(region.y + y));
      ids[static_cast<size_t>(y) * (rw + 1) + x] =
          objects.nearest({eye_, corner_ray(region.x + x, region.y + y)}, at).object;
    }
  }
  double ball_area = 0.0;
  for (int y = 0; y < rh; ++y) {
    for (int x = 0; x < rw; ++x) {
      const size_t i = static_cast<size_t>(y) * (rw + 1) + x;
      const int a = ids[i], b = ids[i + 1], c = ids[i + rw + 1], d = ids[i + rw + 2];
      const int px = region.x + x, py = region.y + y;
      const auto &ra = corner_ray(px, py), &rb = corner_ray(px + 1, py),
                 &rc = corner_ray(px, py + 1), &rd = corner_ray(px + 1, py + 1);
      double coverage = 0.0;
      if (a == b && a == c && a == d) {  // one object over the whole pixel: one ray
        if (a < 0) continue;
        const Ray ray{eye_, blend(ra, rb, rc, rd, 0.5, 0.5)};
        const Hit hit = objects.nearest(ray, cv::Point2f(px + 0.5f, py + 0.5f));
        if (hit.object < 0) continue;
        image.at<cv::Vec3b>(py, px) = to_pixel(objects.colour(hit, ray, to_light_));
        coverage = hit.object == 0 ? 1.0 : 0.0;
      } else {  // an edge crosses the pixel: kSuper x kSuper rays
        const Eigen::Vector3d behind = from_pixel(background_.at<cv::Vec3b>(py, px));
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        int on_ball = 0;
        for (int sy = 0; sy < kSuper; ++sy) {
          for (int sx = 0; sx < kSuper; ++sx) {
            const double u = (sx + 0.5) / kSuper, v = (sy + 0.5) / kSuper;
            const Ray ray{eye_, blend(ra, rb, rc, rd, u, v)};
            const Hit hit = objects.nearest(
                ray, cv::Point2f(static_cast<float>(px + u), static_cast<float>(py + v)));
            sum += hit.object < 0 ? behind : objects.colour(hit, ray, to_light_);
            on_ball += hit.object == 0;
          }
        }
        image.at<cv::Vec3b>(py, px) = to_pixel(sum / (kSuper * kSuper));
        coverage = static_cast<double>(on_ball) / (kSuper * kSuper);
      }
      if (ball_coverage != nullptr) ball_coverage->at<float>(y, x) = static_cast<float>(coverage);
      ball_area += coverage;
    }
  }
  return ball_area;
}

double CameraRenderer::hidden_by_panel(const DynamicScene& scene, const cv::Rect& region,
                                       const cv::Mat& ball_coverage, cv::Mat& image) const {
  if (!scene.panel) return 0.0;
  std::vector<cv::Point> corners;
  for (const Eigen::Vector3d& p : *scene.panel) {
    const auto pixel = camera_.project(p);
    if (!pixel) return 0.0;
    corners.emplace_back(cvRound(pixel->x() * 16), cvRound(pixel->y() * 16));  // 4 fraction bits
  }
  const cv::Scalar colour(scene.panel_colour.x(), scene.panel_colour.y(), scene.panel_colour.z());
  cv::fillConvexPoly(image, corners, colour, cv::LINE_AA, 4);
  if (ball_coverage.empty()) return 0.0;
  cv::Mat mask = cv::Mat::zeros(region.size(), CV_8U);
  for (cv::Point& p : corners) p -= cv::Point(region.x * 16, region.y * 16);
  cv::fillConvexPoly(mask, corners, cv::Scalar(255), cv::LINE_AA, 4);
  cv::Mat covered;
  mask.convertTo(covered, CV_32F, 1.0 / 255);
  return cv::sum(covered.mul(ball_coverage))[0];
}

void CameraRenderer::apply_exposure(const DynamicScene& scene, cv::Mat& image) const {
  const Eigen::Vector3d g = scene.gain * scene.colour_gain;
  if ((g - Eigen::Vector3d::Ones()).cwiseAbs().maxCoeff() > 1e-6) {
    cv::multiply(image, cv::Scalar(g.x(), g.y(), g.z()), image);
  }
  const size_t k =
      static_cast<size_t>(((scene.noise_frame % kNoiseFrames) + kNoiseFrames) % kNoiseFrames);
  cv::add(image, noise_up_[k], image);
  cv::subtract(image, noise_down_[k], image);
}

struct CameraRenderer::BallImage {
  cv::Rect region;             // where the ball was drawn
  cv::Mat coverage;            // CV_32F over `region`: the fraction of each pixel on the ball
  double silhouette_px = 0.0;  // the ball's area, pixels
};

std::vector<std::pair<cv::Rect, bool>> CameraRenderer::screen_regions(
    const DynamicScene& scene, Objects& objects, std::vector<cv::Rect>& ball_screens) const {
  std::vector<std::pair<cv::Rect, bool>> regions;  // (region, holds the ball)
  for (const Eigen::Vector3d& c : scene.ball_centres) {
    if (auto box = screen_box(sphere_cube(c, scene.ball_radius))) {
      regions.emplace_back(*box, true);
      ball_screens.push_back(*box);
    } else {
      ball_screens.emplace_back();
    }
  }
  objects.screen.resize(1 + scene.boxes.size());
  for (size_t i = 0; i < scene.boxes.size(); ++i) {
    const auto corners = scene.boxes[i].corners();
    if (auto r = screen_box({corners.begin(), corners.end()})) {
      regions.emplace_back(*r, false);
      objects.screen[i + 1] = *r;
    }
  }
  return regions;
}

CameraRenderer::BallImage CameraRenderer::render_sharp(
    const DynamicScene& scene, const std::vector<std::pair<cv::Rect, bool>>& regions,
    const std::vector<cv::Rect>& ball_screens, Objects& objects, cv::Mat& image) const {
  BallImage ball;
  objects.has_ball = !scene.ball_centres.empty();
  if (objects.has_ball) {
    objects.ball = {scene.ball_centres.front(), scene.ball_radius, scene.ball_material};
    objects.screen[0] = ball_screens.front();
  }
  for (const auto& [region, is_ball] : regions) {
    if (is_ball) {
      ball.region = region;
      ball.coverage = cv::Mat::zeros(region.size(), CV_32F);
      ball.silhouette_px = render_region(objects, region, image, &ball.coverage);
    } else {
      render_region(objects, region, image, nullptr);
    }
  }
  return ball;
}

CameraRenderer::BallImage CameraRenderer::render_blurred(
    const DynamicScene& scene, const std::vector<std::pair<cv::Rect, bool>>& regions,
    const std::vector<cv::Rect>& ball_screens, Objects& objects, cv::Mat& image) const {
  BallImage ball;
  cv::Rect all;
  for (const auto& [region, is_ball] : regions) all = all.empty() ? region : (all | region);
  cv::Mat sum = cv::Mat::zeros(all.size(), CV_32FC3);
  ball.coverage = cv::Mat::zeros(all.size(), CV_32F);
  for (size_t s = 0; s < scene.ball_centres.size(); ++s) {
    objects.has_ball = true;
    objects.ball = {scene.ball_centres[s], scene.ball_radius, scene.ball_material};
    objects.screen[0] = ball_screens[s];
    cv::Mat pass = image.clone(), coverage = cv::Mat::zeros(all.size(), CV_32F);
    ball.silhouette_px += render_region(objects, all, pass, &coverage);
    cv::accumulate(pass(all), sum);
    ball.coverage += coverage;
  }
  const double n = static_cast<double>(scene.ball_centres.size());
  sum.convertTo(image(all), CV_8UC3, 1.0 / n);
  ball.coverage /= n;
  ball.silhouette_px /= n;
  ball.region = all;
  return ball;
}

BallVisibility CameraRenderer::render(const DynamicScene& scene, cv::Mat& image) const {
  background_.copyTo(image);
  Objects objects;
  objects.boxes = &scene.boxes;
  objects.prepare(eye_, to_light_);
  std::vector<cv::Rect> ball_screens;  // per ball centre; empty where it is not drawn
  std::vector<std::pair<cv::Rect, bool>> regions = screen_regions(scene, objects, ball_screens);
  merge_overlapping(regions);
  const BallImage ball = scene.ball_centres.size() <= 1
                             ? render_sharp(scene, regions, ball_screens, objects, image)
                             : render_blurred(scene, regions, ball_screens, objects, image);
  BallVisibility seen;
  seen.silhouette_px = ball.silhouette_px;
  seen.visible_px = seen.silhouette_px - hidden_by_panel(scene, ball.region, ball.coverage, image);
  apply_exposure(scene, image);
  return seen;
}

cv::Mat CameraRenderer::ball_coverage(const Eigen::Vector3d& centre, double radius) const {
  cv::Mat coverage = cv::Mat::zeros(camera_.height(), camera_.width(), CV_32F);
  Objects objects;
  const std::vector<Box> none;
  objects.boxes = &none;
  objects.has_ball = true;
  objects.ball.centre = centre;
  objects.ball.radius = radius;
  cv::Mat scratch = background_.clone();
  if (auto region = screen_box(sphere_cube(centre, radius))) {
    objects.screen = {*region};
    cv::Mat roi = coverage(*region);
    render_region(objects, *region, scratch, &roi);
  }
  return coverage;
}

}  // namespace sg::sim
