#include "sim/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sg::sim {

std::optional<double> Sphere::intersect(const Ray& ray) const {
  const Eigen::Vector3d oc = ray.origin - centre;
  const double b = oc.dot(ray.direction);
  const double c = oc.squaredNorm() - radius * radius;
  const double disc = b * b - c;
  if (disc < 0) return std::nullopt;
  const double root = std::sqrt(disc);
  double t = -b - root;
  if (t <= 0) t = -b + root;
  if (t <= 0) return std::nullopt;
  return t;
}

std::optional<double> Box::intersect(const Ray& ray) const {
  // Cheap rejection first: the ray must pass within the box's bounding sphere.
  const Eigen::Vector3d to_centre = pose.translation() - ray.origin;
  const double along = to_centre.dot(ray.direction);
  if (to_centre.squaredNorm() - along * along > half_size.squaredNorm()) return std::nullopt;
  const Eigen::Matrix3d world_to_box = pose.linear().transpose();
  const Eigen::Vector3d o = world_to_box * (ray.origin - pose.translation());
  const Eigen::Vector3d d = world_to_box * ray.direction;
  double near = -std::numeric_limits<double>::infinity();
  double far = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-12) {
      if (std::abs(o[i]) > half_size[i]) return std::nullopt;
      continue;
    }
    double t0 = (-half_size[i] - o[i]) / d[i];
    double t1 = (half_size[i] - o[i]) / d[i];
    if (t0 > t1) std::swap(t0, t1);
    near = std::max(near, t0);
    far = std::min(far, t1);
    if (near > far) return std::nullopt;
  }
  if (far <= 0) return std::nullopt;
  return near > 0 ? near : far;
}

Eigen::Vector3d Box::normal_at(const Eigen::Vector3d& point) const {
  const Eigen::Vector3d local = pose.linear().transpose() * (point - pose.translation());
  int axis = 0;
  double best = -1;
  for (int i = 0; i < 3; ++i) {
    const double closeness = std::abs(local[i]) / half_size[i];
    if (closeness > best) best = closeness, axis = i;
  }
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n[axis] = local[axis] > 0 ? 1 : -1;
  return pose.linear() * n;
}

std::array<Eigen::Vector3d, 8> Box::corners() const {
  std::array<Eigen::Vector3d, 8> out;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d local((i & 1 ? 1 : -1) * half_size.x(), (i & 2 ? 1 : -1) * half_size.y(),
                                (i & 4 ? 1 : -1) * half_size.z());
    out[static_cast<size_t>(i)] = pose * local;
  }
  return out;
}

Eigen::Vector3d shade(const Material& m, const Eigen::Vector3d& normal,
                      const Eigen::Vector3d& view_direction, const Eigen::Vector3d& to_light) {
  const double lambert = std::max(0.0, normal.dot(to_light));
  Eigen::Vector3d colour = m.albedo * (m.ambient + m.diffuse * lambert) * 255.0;
  if (m.specular > 0 && lambert > 0) {
    const Eigen::Vector3d half = (to_light - view_direction).normalized();
    const double highlight = std::pow(std::max(0.0, normal.dot(half)), m.shininess);
    colour += Eigen::Vector3d::Constant(255.0 * m.specular * highlight);
  }
  return colour;
}

Eigen::Matrix3d rotation_from_rpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace sg::sim
