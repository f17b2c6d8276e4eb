// Scenario kinematics against their closed forms.

#include "sim/scenario.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sg::sim {
namespace {

ScenarioParams paper(double phase = 0.3) {
  ScenarioParams p;
  p.phase = phase;
  return p;
}

// The paper's drift: 0 at t = 0, reversing at 10, 30, 50 s at +-0.1 m, moving at 0.01 m/s.
TEST(Scenario, DriftIsATriangleWaveReversingEvery20s) {
  EXPECT_NEAR(triangle_drift(0, 0.01, 20), 0.0, 1e-15);
  EXPECT_NEAR(triangle_drift(5, 0.01, 20), 0.05, 1e-15);
  EXPECT_NEAR(triangle_drift(10, 0.01, 20), 0.1, 1e-15);
  EXPECT_NEAR(triangle_drift(20, 0.01, 20), 0.0, 1e-15);
  EXPECT_NEAR(triangle_drift(30, 0.01, 20), -0.1, 1e-15);
  EXPECT_NEAR(triangle_drift(50, 0.01, 20), 0.1, 1e-15);
  for (double t : {1.0, 12.0, 29.0, 31.0, 49.0, 51.0, 1234.5}) {  // speed is 0.01 m/s throughout
    const double v =
        (triangle_drift(t + 1e-3, 0.01, 20) - triangle_drift(t - 1e-3, 0.01, 20)) / 2e-3;
    EXPECT_NEAR(std::abs(v), 0.01, 1e-9) << t;
  }
  EXPECT_GT(triangle_drift(9.9, 0.01, 20), triangle_drift(9.8, 0.01, 20));    // rising before 10
  EXPECT_LT(triangle_drift(10.2, 0.01, 20), triangle_drift(10.1, 0.01, 20));  // falling after
}

// paper = a circle of radius 0.15 m at 1 rpm in the plane Z = centre.z, plus the drift along Y.
TEST(Scenario, PaperIsCirclePlusDrift) {
  const auto s = make_scenario(paper());
  const Eigen::Vector3d c(0.45, 0.0, 0.10);
  for (double t = 0; t < 200; t += 0.25) {
    const Eigen::Vector3d on_circle =
        s->position(t) - c - Eigen::Vector3d(0, triangle_drift(t, 0.01, 20), 0);
    EXPECT_NEAR(on_circle.norm(), 0.15, 1e-12);
    EXPECT_NEAR(on_circle.z(), 0.0, 1e-15);
    EXPECT_NEAR(std::atan2(on_circle.y(), on_circle.x()),
                std::remainder(0.3 + 2 * M_PI * t / 60.0, 2 * M_PI), 1e-9);
  }
}

// circle repeats every 60 / rpm seconds; figure8 too; line runs between its ends at its speed.
TEST(Scenario, PeriodsAndLine) {
  ScenarioParams p = paper();
  p.kind = "circle";
  p.rpm = 2.0;
  const auto circle = make_scenario(p);
  EXPECT_NEAR((circle->position(7.0) - circle->position(37.0)).norm(), 0.0, 1e-12);
  EXPECT_GT((circle->position(7.0) - circle->position(22.0)).norm(), 0.29);  // half a turn apart
  p.kind = "figure8";
  const auto eight = make_scenario(p);
  EXPECT_NEAR((eight->position(3.0) - eight->position(33.0)).norm(), 0.0, 1e-12);
  p.kind = "line";
  p.line_half_length = 0.1;
  p.line_speed = 0.05;
  const auto line = make_scenario(p);
  EXPECT_NEAR(line->position(0).y(), 0.0, 1e-15);
  EXPECT_NEAR(line->position(2.0).y(), 0.1, 1e-12);   // reaches the end after half_length/speed
  EXPECT_NEAR(line->position(6.0).y(), -0.1, 1e-12);  // and the other end 4 s later
  EXPECT_NEAR(line->position(3.3).x(), 0.45, 1e-15);
}

// random is smooth, bounded, and a function of its seed alone.
TEST(Scenario, RandomIsSeededSmoothAndBounded) {
  ScenarioParams p = paper();
  p.kind = "random";
  p.seed = 11;
  const auto a = make_scenario(p), b = make_scenario(p);
  p.seed = 12;
  const auto c = make_scenario(p);
  double max_speed = 0;
  for (double t = 0; t < 300; t += 0.5) {
    EXPECT_EQ(a->position(t), b->position(t));
    EXPECT_LE((a->position(t) - p.centre).cwiseAbs().maxCoeff(), 1.5 * p.random_extent);
    max_speed = std::max(max_speed, (a->position(t + 0.01) - a->position(t)).norm() / 0.01);
  }
  EXPECT_NE(a->position(5), c->position(5));
  EXPECT_LT(max_speed, 6 * p.random_speed);
  EXPECT_GT(max_speed, 0.2 * p.random_speed);
}

// still stays; an unknown kind is refused with the list of kinds.
TEST(Scenario, StillAndUnknown) {
  ScenarioParams p = paper();
  p.kind = "still";
  EXPECT_EQ(make_scenario(p)->position(123.0), p.centre);
  p.kind = "spiral";
  try {
    make_scenario(p);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'spiral'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("figure8"), std::string::npos);
  }
}

}  // namespace
}  // namespace sg::sim
