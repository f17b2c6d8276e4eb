#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>

namespace sg::sim {

/// How a surface reflects light: Lambert diffuse plus a Blinn-Phong highlight. Colours are BGR in
/// [0, 1].
struct Material {
  Eigen::Vector3d albedo{0.5, 0.5, 0.5};
  double ambient = 0.45;
  double diffuse = 0.6;
  double specular = 0.0;
  double shininess = 40.0;
};

/// A ray from `origin` along unit `direction`.
struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;
};

/// A ball.
struct Sphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.035;
  Material material;

  /// Distance along the ray to the first hit in front of its origin, if any.
  std::optional<double> intersect(const Ray& ray) const;
  Eigen::Vector3d normal_at(const Eigen::Vector3d& point) const {
    return (point - centre) / radius;
  }
};

/// An oriented box: `pose` takes box coordinates to the world; the box spans +-half_size.
struct Box {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Eigen::Vector3d half_size{0.01, 0.01, 0.01};
  Material material;

  /// Distance along the ray to the first hit in front of its origin, if any (slab method).
  std::optional<double> intersect(const Ray& ray) const;
  /// Outward normal at a point on the surface.
  Eigen::Vector3d normal_at(const Eigen::Vector3d& point) const;
  /// The eight corners in the world frame.
  std::array<Eigen::Vector3d, 8> corners() const;
};

/// Colour (BGR, 0-255) of a lit surface point seen along `view_direction` (from the eye).
Eigen::Vector3d shade(const Material& material, const Eigen::Vector3d& normal,
                      const Eigen::Vector3d& view_direction, const Eigen::Vector3d& to_light);

/// Rotation from fixed X-Y-Z angles (roll about X, then pitch about Y, then yaw about Z), the
/// convention of arm_cmd_t and arm_status_t.
Eigen::Matrix3d rotation_from_rpy(const Eigen::Vector3d& rpy);

}  // namespace sg::sim
