// Issue 12's joints and conditions against geometry computed here, apart from the renderer:
// the walls and corners where they must be, the labels on them, the root on the surface, the
// bisector's angle; high-low, tacks, clamps and bars where they must be; the files.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <groovetrace/error.hpp>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "synth/internal.hpp"

namespace gt = groovetrace;

namespace {

constexpr double kPi = 3.14159265358979323846;
// The plate (synth.hpp): 300 x 200 mm on the table, the seam along x through the origin.
constexpr double kPlateHalfX = 0.15, kPlateHalfY = 0.10;
// Float coordinates of the cloud are good to about 1e-7 m at 0.4 m.
constexpr double kOn = 2e-6;

gt::SynthParams quiet(gt::Shape shape, gt::JointType joint, int width = 640, int height = 480) {
  gt::SynthParams p;
  p.shape = shape;
  p.joint = joint;
  p.width = width;
  p.height = height;
  p.noise = false;
  return p;
}

// Noise-free points in the workpiece frame, with their labels.
struct WorkpiecePoints {
  std::vector<Eigen::Vector3d> p;
  std::vector<std::uint8_t> label;
};
WorkpiecePoints workpiece_points(const gt::SynthScan& s) {
  WorkpiecePoints w;
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    w.p.push_back(s.truth.T_workpiece_camera * s.cloud.point(i).cast<double>());
    w.label.push_back(s.truth.label[i]);
  }
  return w;
}

bool inside_plate(const Eigen::Vector3d& q, double margin) {
  return std::abs(q.x()) < kPlateHalfX - margin && std::abs(q.y()) < kPlateHalfY - margin;
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / kPi;
}

std::string temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("gt-synthj-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace

// A 45 deg single bevel without gap: its walls are the plane y = 0 (vertical, the -y part's)
// and the plane y = z - (T - D) (45 deg, the +y part's), meeting at the root; nothing labelled
// lies on the -y side of the vertical wall.
TEST(SynthJoints, BevelWallsRootAndBisector) {
  gt::SynthParams p = quiet(gt::Shape::kStraight, gt::JointType::kBevel);
  p.groove_angle_deg = 45.0;
  p.root_gap = 0.0;
  p.groove_width = 0.008;
  p.tilt_deg = -20.0;  // the camera on the +y side, facing the vertical wall
  const gt::SynthScan s = gt::render(p);
  const gt::GrooveGeometry& g = s.truth.groove;
  ASSERT_NEAR(g.depth, 0.008, 1e-12) << "a 45 deg bevel is as deep as it is wide";
  const double T = g.thickness, root_z = T - g.depth;
  const WorkpiecePoints w = workpiece_points(s);
  std::size_t vertical = 0, inclined = 0;
  for (std::size_t i = 0; i < w.p.size(); ++i) {
    const Eigen::Vector3d& q = w.p[i];
    if (!w.label[i] || !inside_plate(q, 0.002)) continue;
    EXPECT_GE(q.y(), -kOn) << "labelled point behind the vertical wall";
    EXPECT_GE(q.z(), root_z - kOn);
    const bool on_vertical = std::abs(q.y()) < kOn;
    const bool on_inclined = std::abs(q.y() - (q.z() - root_z)) < kOn;
    EXPECT_TRUE(on_vertical || on_inclined) << q.transpose();
    vertical += on_vertical;
    inclined += on_inclined;
  }
  EXPECT_GT(vertical, 200u);
  EXPECT_GT(inclined, 1000u);
  // The top beside the groove is not labelled and flat.
  for (std::size_t i = 0; i < w.p.size(); ++i) {
    const Eigen::Vector3d& q = w.p[i];
    if (!inside_plate(q, 0.002) || (q.y() > -0.001 && q.y() < g.top_width + 0.001)) continue;
    EXPECT_EQ(w.label[i], 0);
    EXPECT_NEAR(q.z(), T, kOn);
  }
  // Root: on the surface where the walls meet; bisector 22.5 deg off the plate's normal,
  // towards the inclined wall: the mean of the walls' upward directions.
  const gt::SynthScene scene(p);
  const gt::Seam& seam = s.truth.seams.at(0);
  EXPECT_EQ(seam.joint, gt::JointType::kBevel);
  const Eigen::Isometry3d& T_wc = s.truth.T_workpiece_camera;
  const Eigen::Vector3d walls = Eigen::Vector3d(0, 0, 1) + Eigen::Vector3d(0, 1, 1).normalized();
  // Away from the plate's ends, where the part's end faces meet the root.
  for (std::size_t k = 5; k + 5 < seam.root.size(); k += 25) {
    const Eigen::Vector3d r = T_wc * seam.root[k];
    EXPECT_NEAR(r.y(), 0.0, 1e-12);
    EXPECT_NEAR(r.z(), root_z, 1e-12);
    EXPECT_NEAR(scene.signed_distance(r), 0.0, 1e-9);
    EXPECT_LT(scene.signed_distance(r + Eigen::Vector3d(0, -1e-4, 1e-5)), 0.0) << "-y part";
    EXPECT_LT(scene.signed_distance(r + Eigen::Vector3d(0, 1e-4, 5e-5)), 0.0) << "+y part";
    EXPECT_GT(scene.signed_distance(r + Eigen::Vector3d(0, 1e-4, 2e-4)), 0.0) << "groove";
    const Eigen::Vector3d b = T_wc.linear() * seam.bisector[k];
    EXPECT_NEAR(angle_deg(b, Eigen::Vector3d::UnitZ()), 22.5, 1e-9);
    EXPECT_NEAR(angle_deg(b, walls), 0.0, 1e-6);
    EXPECT_NEAR((T_wc.linear() * seam.normal[k] - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
  }
  EXPECT_NEAR(seam.length_in_view(), seam.length(), 1e-9);
}

// A T-joint: the web stands on y in [0, 10 mm]; the seam is the corner (y = 0, z = T), the
// joint region the faces within a leg W / sqrt(2) of it; the camera looks down the bisector.
TEST(SynthJoints, FilletCornerRegionAndView) {
  const gt::SynthParams p = quiet(gt::Shape::kStraight, gt::JointType::kFillet);
  const gt::SynthScan s = gt::render(p);
  const double T = s.truth.groove.thickness, leg = p.groove_width / std::sqrt(2.0);
  EXPECT_NEAR(s.truth.groove.depth, 0.5 * p.groove_width, 1e-12) << "throat";
  const WorkpiecePoints w = workpiece_points(s);
  std::size_t base = 0, web = 0, web_top = 0;
  for (std::size_t i = 0; i < w.p.size(); ++i) {
    const Eigen::Vector3d& q = w.p[i];
    if (!inside_plate(q, 0.002)) continue;
    const bool on_base = std::abs(q.z() - T) < kOn && q.y() < kOn;
    const bool on_web = std::abs(q.y()) < kOn && q.z() > T - kOn;
    if (w.label[i]) {
      EXPECT_TRUE((on_base && q.y() > -leg - kOn) || (on_web && q.z() < T + leg + kOn))
          << q.transpose();
      base += on_base;
      web += on_web;
    } else if (on_base) {
      EXPECT_LT(q.y(), -leg + kOn) << "unlabelled base top inside the region";
    } else if (on_web) {
      EXPECT_GT(q.z(), T + leg - kOn) << "unlabelled web face inside the region";
    }
    if (std::abs(q.z() - (T + 0.05)) < kOn) {
      EXPECT_GT(q.y(), -kOn);
      EXPECT_LT(q.y(), 0.010 + kOn);
      ++web_top;
    }
  }
  EXPECT_GT(base, 1000u);
  EXPECT_GT(web, 1000u);
  EXPECT_GT(web_top, 1000u) << "the web is 50 mm high";
  const gt::SynthScene scene(p);
  const gt::Seam& seam = s.truth.seams.at(0);
  EXPECT_EQ(seam.joint, gt::JointType::kFillet);
  const Eigen::Isometry3d& T_wc = s.truth.T_workpiece_camera;
  const Eigen::Vector3d bisector = Eigen::Vector3d(0, -1, 1).normalized();
  for (std::size_t k = 0; k < seam.root.size(); k += 25) {
    const Eigen::Vector3d r = T_wc * seam.root[k];
    EXPECT_NEAR(r.y(), 0.0, 1e-12);
    EXPECT_NEAR(r.z(), T, 1e-12);
    EXPECT_NEAR(scene.signed_distance(r), 0.0, 1e-9);
    const Eigen::Vector3d b = T_wc.linear() * seam.bisector[k];
    EXPECT_NEAR(angle_deg(b, Eigen::Vector3d::UnitZ()), 45.0, 1e-9);
    EXPECT_NEAR(angle_deg(b, bisector), 0.0, 1e-9);
    EXPECT_NEAR((seam.normal[k] - seam.bisector[k]).norm(), 0.0, 1e-12);
  }
  // At tilt 0 the camera looks along -bisector at the corner; the whole seam is in view.
  EXPECT_NEAR(angle_deg(T_wc.linear().col(2), -bisector), 0.0, 1e-9);
  EXPECT_LT(T_wc.translation().y(), 0.0);
  EXPECT_NEAR(seam.length_in_view(), seam.length(), 1e-9);
}

// A lap: a second plate of thickness T lies on y >= 0; its edge face and the lower plate's
// top meet at the seam.
TEST(SynthJoints, LapCornerAndUpperPlate) {
  const gt::SynthParams p = quiet(gt::Shape::kStraight, gt::JointType::kLap);
  const gt::SynthScan s = gt::render(p);
  const double T = s.truth.groove.thickness, leg = p.groove_width / std::sqrt(2.0);
  const WorkpiecePoints w = workpiece_points(s);
  std::size_t labelled = 0, upper = 0;
  for (std::size_t i = 0; i < w.p.size(); ++i) {
    const Eigen::Vector3d& q = w.p[i];
    if (!inside_plate(q, 0.002)) continue;
    if (w.label[i]) {
      const bool on_base = std::abs(q.z() - T) < kOn && q.y() < kOn && q.y() > -leg - kOn;
      const bool on_edge = std::abs(q.y()) < kOn && q.z() > T - kOn && q.z() < T + leg + kOn;
      EXPECT_TRUE(on_base || on_edge) << q.transpose();
      ++labelled;
    } else if (q.y() > 0.001) {
      EXPECT_NEAR(q.z(), 2 * T, kOn) << "the upper plate's top";
      ++upper;
    } else if (q.y() < -leg - 0.001) {
      EXPECT_NEAR(q.z(), T, kOn);
    }
  }
  EXPECT_GT(labelled, 1000u);
  EXPECT_GT(upper, 10000u);
  const gt::Seam& seam = s.truth.seams.at(0);
  EXPECT_EQ(seam.joint, gt::JointType::kLap);
  const Eigen::Vector3d b = s.truth.T_workpiece_camera.linear() * seam.bisector.at(0);
  EXPECT_NEAR(angle_deg(b, Eigen::Vector3d(0, -1, 1)), 0.0, 1e-9);
}

// The fillet's web follows curved and bent paths; every plate shape with every joint renders
// a labelled joint and its seams.
TEST(SynthJoints, EveryJointOnItsShapes) {
  using J = gt::JointType;
  using S = gt::Shape;
  const std::vector<std::pair<S, J>> cases = {{S::kCurve, J::kFillet},   {S::kLShape, J::kFillet},
                                              {S::kMulti, J::kFillet},   {S::kBox, J::kFillet},
                                              {S::kCurve, J::kLap},      {S::kLShape, J::kLap},
                                              {S::kCurve, J::kBevel},    {S::kCylinder, J::kBevel},
                                              {S::kPipeLong, J::kBevel}, {S::kMulti, J::kBevel}};
  for (const auto& [shape, joint] : cases) {
    gt::SynthParams p = quiet(shape, joint, 320, 240);
    if (joint == J::kBevel) p.groove_angle_deg = 45.0;
    const gt::SynthScan s = gt::render(p);
    std::size_t labelled = 0;
    for (std::size_t i = 0; i < s.cloud.size(); ++i) labelled += s.truth.label[i];
    const std::string what = std::string(gt::shape_name(shape)) + " " + gt::joint_name(joint);
    EXPECT_GT(labelled, 100u) << what;
    ASSERT_EQ(s.truth.seams.size(), shape == S::kMulti ? 2u : 1u) << what;
    const gt::SynthScene scene(p);
    for (const gt::Seam& seam : s.truth.seams) {
      EXPECT_EQ(seam.joint, joint) << what;
      EXPECT_GT(seam.length_in_view(), 0.05) << what;
      for (std::size_t k = 0; k < seam.root.size(); k += 20) {
        const Eigen::Vector3d r = s.truth.T_workpiece_camera * seam.root[k];
        const double tol = joint == J::kBevel ? 0.5 * p.root_gap + 1e-9 : 1e-9;
        EXPECT_LE(std::abs(scene.signed_distance(r)), tol) << what << " vertex " << k;
        const double off = angle_deg(seam.bisector[k], seam.normal[k]);
        EXPECT_NEAR(off, joint == J::kBevel ? 22.5 : 0.0, 1e-6) << what;
      }
    }
  }
}

// High-low: the +y part's top is higher by exactly the misalignment; the V's +y wall runs on
// up to it (labelled), the -y side is unchanged.
TEST(SynthConditions, MisalignmentRaisesThePlusYTop) {
  gt::SynthParams p = quiet(gt::Shape::kStraight, gt::JointType::kV);
  p.misalignment = 0.0015;
  p.root_gap = 0.0;
  const gt::SynthScan s = gt::render(p);
  const gt::GrooveGeometry& g = s.truth.groove;
  EXPECT_DOUBLE_EQ(g.misalignment, 0.0015);
  const double T = g.thickness, root_z = T - g.depth;
  const double k = 0.5 * g.top_width / g.depth;  // wall run per depth (no gap)
  const double plus_edge = k * (g.depth + p.misalignment);
  const WorkpiecePoints w = workpiece_points(s);
  std::size_t minus = 0, plus = 0, extension = 0;
  for (std::size_t i = 0; i < w.p.size(); ++i) {
    const Eigen::Vector3d& q = w.p[i];
    if (!inside_plate(q, 0.002)) continue;
    if (q.y() < -0.5 * g.top_width - 0.001) {
      EXPECT_NEAR(q.z(), T, kOn);
      EXPECT_EQ(w.label[i], 0);
      ++minus;
    } else if (q.y() > plus_edge + 0.001) {
      EXPECT_NEAR(q.z(), T + p.misalignment, kOn);
      EXPECT_EQ(w.label[i], 0);
      ++plus;
    } else if (w.label[i] && q.y() > 0.0) {
      EXPECT_NEAR(q.y(), k * (q.z() - root_z), 1e-5) << "on the +y wall";
      extension += q.z() > T + 1e-4;
    }
  }
  EXPECT_GT(minus, 10000u);
  EXPECT_GT(plus, 10000u);
  EXPECT_GT(extension, 50u) << "the +y wall reaches above the -y top";
}

// Tacks fill the V up to their height: every point they change was labelled and stays
// labelled, rises, and lies within a listed tack's length; the highest is the tack's top.
TEST(SynthConditions, TacksRaiseTheGroove) {
  gt::SynthParams p = quiet(gt::Shape::kStraight, gt::JointType::kV);
  p.tilt_deg = 10.0;
  const gt::SynthScan plain = gt::render(p);
  p.tacks = 3;
  const gt::SynthScan s = gt::render(p);
  const gt::Seam& seam = s.truth.seams.at(0);
  ASSERT_EQ(seam.tacks.size(), 3u);
  const Eigen::Isometry3d& T_wc = s.truth.T_workpiece_camera;
  const double root_z = s.truth.groove.thickness - s.truth.groove.depth;
  const double height = 0.7 * s.truth.groove.depth;
  std::vector<double> xs;
  for (std::size_t t = 0; t < seam.tacks.size(); ++t) {
    const gt::Tack& tack = seam.tacks[t];
    EXPECT_GE(tack.length, 0.008);
    EXPECT_LE(tack.length, 0.015);
    EXPECT_NEAR(tack.height, height, 1e-12);
    const Eigen::Vector3d c = T_wc * tack.centre;
    EXPECT_NEAR(c.y(), 0.0, 1e-9);
    EXPECT_NEAR(c.z(), root_z, 1e-9);
    EXPECT_NEAR(tack.position, c.x() + kPlateHalfX, 1e-8) << "arc length from the seam's start";
    if (t > 0) {
      EXPECT_GT(tack.position - seam.tacks[t - 1].position,
                0.5 * (tack.length + seam.tacks[t - 1].length))
          << "tacks do not overlap";
    }
    xs.push_back(c.x());
  }
  std::size_t changed = 0;
  double top = 0.0;
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    if (std::abs(s.cloud.z[i] - plain.cloud.z[i]) < 1e-7) continue;
    ++changed;
    const Eigen::Vector3d q = T_wc * s.cloud.point(i).cast<double>();
    const Eigen::Vector3d q0 = T_wc * plain.cloud.point(i).cast<double>();
    EXPECT_EQ(plain.truth.label[i], 1);
    EXPECT_EQ(s.truth.label[i], 1);
    EXPECT_GT(q.z(), q0.z());
    bool near = false;
    for (std::size_t t = 0; t < xs.size(); ++t)
      near = near || std::abs(q.x() - xs[t]) <= 0.5 * seam.tacks[t].length + 1e-5;
    EXPECT_TRUE(near) << q.transpose();
    top = std::max(top, q.z() - root_z);
  }
  EXPECT_GT(changed, 100u);
  EXPECT_LE(top, height + 1e-6);
  EXPECT_GT(top, 0.95 * height);
}

// Clamps stand on the plate beside the groove, bars lie on the table beside the plate; both
// are solid (they hide what is behind) and unlabelled.
TEST(SynthConditions, ClampsAndClutterAreUnlabelledSolids) {
  gt::SynthParams p = quiet(gt::Shape::kStraight, gt::JointType::kV);
  const gt::SynthScan plain = gt::render(p);
  p.clamps = 2;
  p.clutter = 1;
  const gt::SynthScan s = gt::render(p);
  const Eigen::Isometry3d& T_wc = s.truth.T_workpiece_camera;
  const double T = s.truth.groove.thickness;
  std::size_t clamp = 0, bar = 0;
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    if (std::abs(s.cloud.z[i] - plain.cloud.z[i]) < 1e-7) {
      EXPECT_EQ(s.truth.label[i], plain.truth.label[i]);
      continue;
    }
    const Eigen::Vector3d q = T_wc * s.cloud.point(i).cast<double>();
    EXPECT_EQ(s.truth.label[i], 0) << q.transpose();
    EXPECT_LT(s.cloud.z[i], plain.cloud.z[i]) << "nearer: something stands there";
    if (std::abs(q.z() - (T + 0.025)) < kOn) {
      // A clamp's top: 5-15 mm beside the groove's edge, 20 mm across.
      EXPECT_GT(std::abs(q.y()), 0.005 + 0.005 - kOn);
      EXPECT_LT(std::abs(q.y()), 0.005 + 0.015 + 0.020 + kOn);
      ++clamp;
    }
    if (std::abs(q.z() - 0.020) < kOn) {
      EXPECT_GT(std::abs(q.y()), kPlateHalfY);
      ++bar;
    }
  }
  EXPECT_GT(clamp, 500u);
  EXPECT_GT(bar, 1000u);
}

// Issue 12's wide scenes: a 100 mm, 150 deg panel joint keeps flat top on both sides in view;
// a 2 mm root opening shows the table through it, labelled; the pipe's diameter is a param.
TEST(SynthConditions, WideGroovesOpenRootsAndPipeDiameter) {
  gt::SynthParams p = quiet(gt::Shape::kStraight, gt::JointType::kV);
  p.groove_width = 0.100;
  p.groove_angle_deg = 150.0;
  gt::SynthScan s = gt::render(p);
  EXPECT_NEAR(s.truth.groove.depth, 0.0995 / (2 * std::tan(75 * kPi / 180)), 1e-12);
  std::size_t left = 0, right = 0;
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    const Eigen::Vector3d q = s.truth.T_workpiece_camera * s.cloud.point(i).cast<double>();
    if (!inside_plate(q, 0.002) || std::abs(q.z() - s.truth.groove.thickness) > kOn) continue;
    (q.y() < 0 ? left : right) += 1;
    EXPECT_GT(std::abs(q.y()), 0.05 - 1e-5);
  }
  EXPECT_GT(left, 10000u);
  EXPECT_GT(right, 10000u);

  p = quiet(gt::Shape::kStraight, gt::JointType::kV);
  p.root_gap = 0.002;
  p.distance = 0.70;
  s = gt::render(p);
  std::size_t table = 0;
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    const Eigen::Vector3d q = s.truth.T_workpiece_camera * s.cloud.point(i).cast<double>();
    if (std::abs(q.z()) < kOn && inside_plate(q, 0.002)) {
      EXPECT_EQ(s.truth.label[i], 1);
      EXPECT_LE(std::abs(q.y()), 0.001 + kOn);
      ++table;
    }
  }
  EXPECT_GT(table, 100u);
  EXPECT_NEAR(s.truth.seams.at(0).length_in_view(), 0.30, 1e-9);

  p = quiet(gt::Shape::kCylinder, gt::JointType::kV);
  p.pipe_diameter = 0.079;
  p.groove_angle_deg = 140.0;
  p.groove_width = 0.012;
  s = gt::render(p);
  const double R = 0.0395;
  for (const Eigen::Vector3d& c : s.truth.seams.at(0).root) {
    const Eigen::Vector3d r = s.truth.T_workpiece_camera * c;
    EXPECT_NEAR(std::hypot(r.y(), r.z() - R), R - s.truth.groove.depth, 1e-12);
  }
}

TEST(SynthParams, RejectsBadJointAndConditionValues) {
  const auto bad = [](auto change, const std::string& name) {
    gt::SynthParams p;
    change(p);
    try {
      gt::validate(p);
      ADD_FAILURE() << "accepted; expected an error naming " << name;
    } catch (const gt::UsageError& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  using J = gt::JointType;
  bad([](gt::SynthParams& p) { p.misalignment = 0.006; }, "misalignment");
  bad([](gt::SynthParams& p) { p.misalignment = -0.001; }, "misalignment");
  bad([](gt::SynthParams& p) { p.misalignment = NAN; }, "misalignment");
  bad([](gt::SynthParams& p) { p.tacks = 11; }, "tacks");
  bad([](gt::SynthParams& p) { p.tacks = -1; }, "tacks");
  bad([](gt::SynthParams& p) { p.tack_height_fraction = 1.5; }, "tack height fraction");
  bad([](gt::SynthParams& p) { p.clamps = 5; }, "clamps");
  bad([](gt::SynthParams& p) { p.clutter = 3; }, "clutter");
  bad([](gt::SynthParams& p) { p.pipe_diameter = 0.05; }, "pipe diameter");
  bad([](gt::SynthParams& p) { p.groove_width = 0.11; }, "groove width");
  bad([](gt::SynthParams& p) { p.groove_angle_deg = 175; }, "groove angle");
  bad(
      [](gt::SynthParams& p) {
        p.joint = J::kBevel;
        p.groove_angle_deg = 85;
      },
      "groove angle");
  bad(
      [](gt::SynthParams& p) {
        p.joint = J::kFillet;
        p.shape = gt::Shape::kCylinder;
      },
      "joint fillet");
  bad(
      [](gt::SynthParams& p) {
        p.joint = J::kLap;
        p.shape = gt::Shape::kMulti;
      },
      "joint lap");
  bad(
      [](gt::SynthParams& p) {
        p.joint = J::kFillet;
        p.misalignment = 0.001;
      },
      "misalignment");
  bad(
      [](gt::SynthParams& p) {
        p.shape = gt::Shape::kPipeLong;
        p.clamps = 1;
      },
      "clamps");
  EXPECT_THROW(gt::parse_joint("butt"), gt::UsageError);
  EXPECT_EQ(gt::parse_joint("v"), J::kV);
  for (J j : {J::kV, J::kBevel, J::kFillet, J::kLap})
    EXPECT_EQ(gt::parse_joint(gt::joint_name(j)), j);
  gt::SynthParams wide;
  wide.groove_width = 0.10;
  wide.groove_angle_deg = 170;
  EXPECT_NO_THROW(gt::validate(wide));
}

TEST(SynthFiles, JointTruthRoundTripAndOlderFiles) {
  gt::SynthParams p = quiet(gt::Shape::kStraight, gt::JointType::kBevel, 160, 120);
  p.groove_angle_deg = 45;
  p.misalignment = 0.001;
  p.tacks = 2;
  p.tack_height_fraction = 0.5;
  p.clutter = 1;
  const gt::SynthScan s = gt::render(p);
  const std::string dir = temp_dir("truth");
  const gt::SynthFiles f = gt::write_synth_scan(s, dir + "/scan.pcd");
  const gt::SynthTruth t = gt::read_synth_truth(f.scan);
  EXPECT_EQ(t.params.joint, gt::JointType::kBevel);
  EXPECT_DOUBLE_EQ(t.params.misalignment, 0.001);
  EXPECT_EQ(t.params.tacks, 2);
  EXPECT_DOUBLE_EQ(t.params.tack_height_fraction, 0.5);
  EXPECT_EQ(t.params.clutter, 1);
  EXPECT_DOUBLE_EQ(t.groove.misalignment, 0.001);
  ASSERT_EQ(t.seams.size(), 1u);
  EXPECT_EQ(t.seams[0].joint, gt::JointType::kBevel);
  ASSERT_EQ(t.seams[0].tacks.size(), 2u);
  EXPECT_DOUBLE_EQ(t.seams[0].tacks[1].position, s.truth.seams[0].tacks[1].position);
  EXPECT_EQ(t.seams[0].tacks[1].centre, s.truth.seams[0].tacks[1].centre);
  EXPECT_EQ(gt::truth_json(t, "scan.pcd", "scan.labels.pcd"),
            gt::truth_json(s.truth, "scan.pcd", "scan.labels.pcd"));
  // The truth file's per-seam record, as documented.
  std::ifstream in(f.truth);
  const nlohmann::json j = nlohmann::json::parse(in);
  const nlohmann::json& seam = j.at("seams").at(0);
  EXPECT_EQ(seam.at("joint"), "bevel");
  EXPECT_DOUBLE_EQ(seam.at("geometry").at("included_angle_deg").get<double>(), 45.0);
  EXPECT_DOUBLE_EQ(seam.at("geometry").at("misalignment_m").get<double>(), 0.001);
  EXPECT_EQ(seam.at("tacks").size(), 2u);
  EXPECT_TRUE(seam.at("tacks").at(0).contains("length_m"));
  // A truth file from before issue 12 reads as a V without tacks.
  nlohmann::json old = j;
  for (const char* key : {"joint", "misalignment_m", "tacks", "tack_height_fraction", "clamps",
                          "clutter", "pipe_diameter_m"})
    old["params"].erase(key);
  old["groove"].erase("misalignment_m");
  for (nlohmann::json& sj : old["seams"]) {
    sj.erase("joint");
    sj.erase("geometry");
    sj.erase("tacks");
  }
  std::ofstream(f.truth) << old.dump();
  const gt::SynthTruth o = gt::read_synth_truth(f.scan);
  EXPECT_EQ(o.params.joint, gt::JointType::kV);
  EXPECT_EQ(o.params.tacks, 0);
  EXPECT_DOUBLE_EQ(o.params.pipe_diameter, 0.10);
  EXPECT_EQ(o.seams.at(0).joint, gt::JointType::kV);
  EXPECT_TRUE(o.seams.at(0).tacks.empty());
  std::filesystem::remove_all(dir);
}

#ifdef GT_CLI_PATH
TEST(SynthCli, JointFlags) {
  const std::string dir = temp_dir("cli");
  const auto run = [&](const std::string& args) {
    const std::string cmd =
        std::string(GT_CLI_PATH) + " synth " + args + " > /dev/null 2> " + dir + "/err.txt";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  ASSERT_EQ(run("--shape straight --joint bevel --tacks 2 --clamps 1 --clutter 1 "
                "--misalignment 0.0015 --tack-height 0.6 --resolution 160x120 --noise off -o " +
                dir + "/b.pcd"),
            0);
  const gt::SynthTruth t = gt::read_synth_truth(dir + "/b.pcd");
  EXPECT_EQ(t.params.joint, gt::JointType::kBevel);
  EXPECT_DOUBLE_EQ(t.params.groove_angle_deg, 45.0) << "the CLI's bevel default";
  EXPECT_DOUBLE_EQ(t.params.misalignment, 0.0015);
  EXPECT_DOUBLE_EQ(t.params.tack_height_fraction, 0.6);
  EXPECT_EQ(t.params.tacks, 2);
  EXPECT_EQ(t.params.clamps, 1);
  EXPECT_EQ(t.params.clutter, 1);
  ASSERT_EQ(run("--shape cylinder --pipe-diameter 0.079 --resolution 160x120 -o " + dir + "/c.pcd"),
            0);
  EXPECT_DOUBLE_EQ(gt::read_synth_truth(dir + "/c.pcd").params.pipe_diameter, 0.079);
  // Bad values: exit 2, one line naming the flag's parameter, no files.
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"--joint butt", "joint"},
      {"--misalignment 0.01", "misalignment"},
      {"--misalignment x", "--misalignment"},
      {"--tacks 11", "tacks"},
      {"--tacks two", "--tacks"},
      {"--tack-height 2", "tack height"},
      {"--clamps 5", "clamps"},
      {"--clutter 3", "clutter"},
      {"--pipe-diameter 0.3", "pipe diameter"},
      {"--groove-width 0.2", "groove width"},
      {"--joint fillet --shape cylinder", "fillet"}};
  for (const auto& [args, name] : bad) {
    const std::string shape = args.find("--shape") == std::string::npos ? "--shape straight " : "";
    EXPECT_EQ(run(shape + args + " -o " + dir + "/x.pcd"), 2) << args;
    std::ifstream err(dir + "/err.txt");
    const std::string text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find(name), std::string::npos) << args << ": " << text;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.pcd"));
  std::filesystem::remove_all(dir);
}
#endif
