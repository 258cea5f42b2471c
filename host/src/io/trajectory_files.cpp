#include <cstdio>
#include <groovetrace/config.hpp>
#include <groovetrace/trajectory_io.hpp>
#include <groovetrace/version.hpp>
#include <nlohmann/json.hpp>

namespace groovetrace {

std::string trajectory_csv(const Trajectory& trajectory) {
  std::string out = "idx,x_m,y_m,z_m,qx,qy,qz,qw,rx,ry,rz\n";
  char line[512];
  for (std::size_t i = 0; i < trajectory.waypoints.size(); ++i) {
    const Waypoint& w = trajectory.waypoints[i];
    const Eigen::Quaterniond& q = w.orientation;
    std::snprintf(line, sizeof line, "%zu,%.7f,%.7f,%.7f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f\n", i,
                  w.position.x(), w.position.y(), w.position.z(), q.x(), q.y(), q.z(), q.w(),
                  w.rotation_vector.x(), w.rotation_vector.y(), w.rotation_vector.z());
    out += line;
  }
  return out;
}

namespace {

std::string tool_frame_text(Method method) {
  const char* z = method == Method::robust ? "-bisector of the two fitted walls"
                                           : "-mean surface normal of the slice";
  return std::string("z along the torch into the workpiece (") + z +
         "), x along the travel direction, y = z cross x";
}

}  // namespace

std::string trajectory_json(const Trajectory& trajectory, const Params& params) {
  using nlohmann::json;
  auto vec = [](const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); };
  json waypoints = json::array();
  for (std::size_t i = 0; i < trajectory.waypoints.size(); ++i) {
    const Waypoint& w = trajectory.waypoints[i];
    const Eigen::Quaterniond& q = w.orientation;
    waypoints.push_back({{"idx", i},
                         {"position_m", vec(w.position)},
                         {"quaternion_xyzw", json::array({q.x(), q.y(), q.z(), q.w()})},
                         {"rotation_vector_rad", vec(w.rotation_vector)},
                         {"euler_zyx_deg", vec(w.euler_zyx_deg)},
                         {"support", w.support}});
  }
  json doc = {
      {"version", version()},
      {"frame", trajectory.frame},
      {"units", {{"position", "m"}, {"rotation_vector", "rad"}, {"euler", "deg"}}},
      {"tool_frame", tool_frame_text(params.method)},
      {"euler_convention", "euler_zyx_deg = [yaw, pitch, roll], R = Rz(yaw) Ry(pitch) Rx(roll)"},
      {"direction", vec(trajectory.direction)},
      {"length_m", trajectory.length},
      {"parameters", json::parse(params_json(params))},
      {"waypoints", waypoints}};
  return doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace groovetrace
