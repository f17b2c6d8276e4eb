#pragma once

/// Where the centre of a sphere images, from its image's apparent centre and radius.
///
/// A sphere's silhouette is a circular cone about the ray to its centre; off the optical axis
/// the image is an ellipse whose major axis points at the principal point, and the ellipse's
/// centre lies farther from the principal point than the projection of the sphere's centre. In
/// the plane of the optical axis and that ray, the two silhouette rays make the same angle alpha
/// either side of it, so the centre's ray bisects them:
///
///     d_centre = (d_1 + d_2) / |d_1 + d_2|,   d_k = ray through c -+ r u,
///
/// with c the apparent centre, a the ellipse's radial semi-axis and u the unit vector from the
/// principal point to c. What is measured is a radius r between the semi-axes (sqrt(a b) from a
/// region's area, about that from a fitted circle); the semi-axes of a sphere's image at
/// off-axis angle theta with half-angle alpha are a = f sin(alpha) cos(alpha) / q and
/// b = f sin(alpha) / sqrt(q), q = cos^2 theta - sin^2 alpha, so a = r sqrt(a / b) is found from
/// the bisector's own theta and alpha in a few rounds. Near the edge of a 560 px lens's view a
/// ball 60 px across images with its centre 1-2 px out; the correction leaves a few hundredths
/// (tests/vision/sphere_image_test.cpp).
///
///     const Eigen::Vector2d px = sphere_centre_pixel(camera, {o.centre.x, o.centre.y}, o.radius);

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "vision/camera_model.hpp"

namespace sg::vision {

/// The pixel of the sphere's centre (see above); `apparent` unchanged when `radius_px` is not
/// positive and finite or `apparent` is within 1e-6 px of the principal point.
Eigen::Vector2d sphere_centre_pixel(const CameraModel& camera, const Eigen::Vector2d& apparent,
                                    double radius_px);

/// The centre BallFitter (ball_fit.hpp) finds on the part `arc` (BallFit::arc) of the exact
/// image of a sphere of radius `radius` (m) centred at `centre` (world frame): the silhouette's
/// tangent points, O + s (a cos(alpha) + (u cos(phi) + v sin(phi)) sin(alpha)) for the camera
/// centre O, the unit ray a to the centre, sin(alpha) = radius / |centre - O| and
/// s = sqrt(|centre - O|^2 - radius^2), projected through the camera (distortion included) at
/// 720 angles phi. The points in the sectors of `arc` (taken about the whole outline's mean,
/// then about the first fit's centre) are fitted with BallFitParams{} as the tracker fits the
/// ball's edge points. Where the gripper hides half the outline of a ball off the optical axis,
/// a circle fitted to the rest of an ellipse lies several px from the centre's projection; the
/// difference this model gives is that error, so
///
///     pixel of the centre = measured + project(centre) - sphere_outline_centre(...)
///
/// With arc = kWholeArc (the tracker's centre is then the region's centroid, eq. 11) it is the
/// centroid of the area the silhouette encloses: the ellipse's centre, as sphere_centre_pixel()
/// models it (a circle does not fit a whole ellipse within BallFitter's 1 px). nullopt
/// when the sphere is not in front of the camera, the camera is inside it, `radius` is not
/// positive and finite, or fewer than 12 outline points fall in `arc`.
std::optional<Eigen::Vector2d> sphere_outline_centre(const CameraModel& camera,
                                                     const Eigen::Vector3d& centre, double radius,
                                                     uint64_t arc);

}  // namespace sg::vision
