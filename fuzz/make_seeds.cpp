// fuzz_seeds OUTDIR: the seed corpus, a few small valid files per harness written by the
// library's own writers and by PCL's (each PCD data type, ASCII and binary PLY, configs and
// calibration files of both syntaxes, a manifest), and libFuzzer dictionaries of each format's
// keywords. Every seed is read back through its reader first: a seed the reader refuses would
// start the fuzzer off the paths that matter, so that is an error here (exit 1).

#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/config.hpp>
#include <groovetrace/frames.hpp>
#include <string>
#include <vector>

#include "batch/jobs.hpp"
#include "depth_png_seed.hpp"
#include "io/depth_png.hpp"
#include "io/text.hpp"

namespace {

namespace fs = std::filesystem;
using groovetrace::Cloud;

// A V-groove 16 points across and 10 along (mm spacing), one point NaN: enough valid points
// for read_cloud's minimum of 100, small enough to keep libFuzzer's inputs short.
Cloud groove_cloud() {
  Cloud c;
  c.width = 16;
  c.height = 10;
  c.resize(160);
  for (std::size_t i = 0; i < c.size(); ++i) {
    const float u = (static_cast<float>(i % 16) - 7.5f) * 0.001f;
    c.x[i] = u;
    c.y[i] = static_cast<float>(i / 16) * 0.001f;
    c.z[i] = 0.3f + std::abs(u);
  }
  c.x[17] = c.y[17] = c.z[17] = NAN;
  c.viewpoint = {0.0f, 0.0f, 0.01f};
  return c;
}

pcl::PointCloud<pcl::PointXYZRGBNormal> pcl_cloud(const Cloud& c, bool organized) {
  pcl::PointCloud<pcl::PointXYZRGBNormal> p;
  p.resize(c.size());
  p.width = organized ? c.width : static_cast<std::uint32_t>(c.size());
  p.height = organized ? c.height : 1;
  for (std::size_t i = 0; i < c.size(); ++i) {
    p[i].x = c.x[i];
    p[i].y = c.y[i];
    p[i].z = c.z[i];
    p[i].r = static_cast<std::uint8_t>(i);
    p[i].normal_z = -1.0f;
  }
  p.is_dense = false;
  return p;
}

void write(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

// The PCDs: binary by our writer (plain and annotated), ascii and binary_compressed by PCL's.
void pcd_seeds(const fs::path& dir) {
  const Cloud c = groove_cloud();
  write(dir / "binary.pcd", groovetrace::pcd_bytes(c));
  const std::vector<float> descriptor(c.size(), 4.5f);
  const std::vector<std::uint8_t> groove(c.size(), 1);
  write(dir / "annotated.pcd",
        groovetrace::annotated_pcd_bytes(c, {nullptr, &descriptor, &groove}));
  fs::create_directories(dir);
  pcl::PCDWriter writer;
  writer.writeASCII((dir / "ascii.pcd").string(), pcl_cloud(c, false), 6);
  writer.writeBinaryCompressed((dir / "binary_compressed.pcd").string(), pcl_cloud(c, true));
  // Integer fields and a COUNT above 1, by hand.
  std::string ints =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z label h\nSIZE 2 2 2 1 4\nTYPE I I U U F\n"
      "COUNT 1 1 1 1 2\nWIDTH 100\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 100\nDATA ascii\n";
  for (int i = 0; i < 100; ++i) {
    ints += std::to_string(i - 50) + " " + std::to_string(i) + " 300 " + std::to_string(i % 2) +
            " 0.5 nan\n";
  }
  write(dir / "integers.pcd", ints);
}

void ply_seeds(const fs::path& dir) {
  fs::create_directories(dir);
  // Dense: PCL's ASCII writer leaves NaN points out but still writes the full grid in its
  // obj_info lines, a file read_cloud refuses (the grid does not hold the vertices).
  Cloud dense = groove_cloud();
  dense.x[17] = dense.y[17] = 0.0f;
  dense.z[17] = 0.3f;
  const auto p = pcl_cloud(dense, false);
  pcl::PLYWriter writer;
  writer.write((dir / "ascii.ply").string(), p, false, false);
  writer.write((dir / "binary.ply").string(), p, true, false);
  // An obj_info grid holding its vertices, and a face element PCL skips.
  std::string grid =
      "ply\nformat ascii 1.0\ncomment by hand\nobj_info num_cols 10\n"
      "obj_info num_rows 12\nelement vertex 120\nproperty float x\n"
      "property double y\nproperty int z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 120; ++i) grid += std::to_string(i) + " 0.5 1\n";
  write(dir / "grid_faces.ply", grid + "3 0 1 2\n");
}

void config_seeds(const fs::path& yaml, const fs::path& json) {
  write(yaml / "robust.yaml",
        "method: robust\nstep: 0.002\nmax_seams: 2\nfillet_leg: 0.007\n"
        "orientation_blend: 0.025\nviewpoint: \"0,0,0.1\"\nunits: mm\nbackend: cpu\n");
  write(yaml / "paper.yaml",
        "# the paper method\nmethod: paper\nthreshold: auto\nradius: 0.003\nsmooth: false\n"
        "slices:\n  - 40\nhand_eye: he.yaml\nflange_pose: fp.yaml\n");
  write(json / "robust.json",
        R"({"method": "robust", "step": 0.002, "max_seams": 2, "units": "mm",)"
        R"( "viewpoint": [0, 0, 0.1], "device": "0", "fillet_leg": 0.007})");
  write(json / "paper.json",
        R"({"method": "paper", "threshold": "auto", "mls_radius": 0.003, "smooth": true,)"
        R"( "min_neighbors": 5, "weld_speed": 0.008})");
}

void calibration_seeds(const fs::path& yaml, const fs::path& json) {
  write(yaml / "hand_eye.yaml", "translation: [0.05, -0.02, 0.1]\nrotation: [0, 0, 0, 1]\n");
  write(yaml / "flange_pose.yaml",
        "# T_base_flange\ntranslation:\n  - 0.4\n  - 0.1\n  - 0.5\n"
        "rotation: [0.7071068, 0, 0, 0.7071068]\n");
  write(json / "hand_eye.json", R"({"translation": [0.05, -0.02, 0.1], "rotation": [0, 0, 0, 1]})");
  write(json / "flange_pose.json",
        R"({"rotation": [0.0, 0.7071068, 0.0, 0.7071068], "translation": [0.4, 0.1, 0.5]})");
  // The other layouts (docs/frames.md), recognised by content whatever the harness names them.
  write(yaml / "easy_handeye.yaml",
        "parameters:\n  eye_on_hand: true\n  robot_effector_frame: tool0\n"
        "  tracking_base_frame: cam\ntransformation:\n  qw: 1.0\n  qx: 0.0\n  qy: 0.0\n"
        "  qz: 0.0\n  x: 0.05\n  y: -0.02\n  z: 0.1\n");
  write(yaml / "easy_handeye2.calib",
        "parameters:\n  calibration_type: eye_in_hand\n  robot_effector_frame: tool0\n"
        "transform:\n  translation:\n    x: 0.05\n    y: -0.02\n    z: 0.1\n"
        "  rotation:\n    x: 0.0\n    y: 0.0\n    z: 0.0\n    w: 1.0\n");
  write(yaml / "ros_pose.yaml",
        "pose:\n  position: {x: 0.4, y: 0.1, z: 0.5}\n"
        "  orientation: {x: 0.0, y: 0.0, z: 0.0, w: 1.0}\n");
  write(yaml / "opencv.yaml",
        "%YAML:1.0\n---\nR_cam2gripper: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]\nt_cam2gripper: !!opencv-matrix\n"
        "   rows: 3\n   cols: 1\n   dt: d\n   data: [ 5.e-02, -2.e-02, 1.e-01 ]\n");
  write(yaml / "opencv.xml",
        "<?xml version=\"1.0\"?>\n<opencv_storage>\n<R type_id=\"opencv-matrix\">\n"
        "  <rows>3</rows>\n  <cols>3</cols>\n  <dt>d</dt>\n  <data>\n"
        "    1. 0. 0. 0. 1. 0. 0. 0. 1.</data></R>\n<t type_id=\"opencv-matrix\">\n"
        "  <rows>3</rows>\n  <cols>1</cols>\n  <dt>d</dt>\n  <data>\n"
        "    5.e-02 -2.e-02 1.e-01</data></t>\n<!-- Tsai -->\n</opencv_storage>\n");
  write(yaml / "matrix.txt", "# rows\n0 -1 0 0.05\n1 0 0 -0.02\n0 0 1 0.1\n0 0 0 1\n");
  write(yaml / "matrix.yaml",
        "- [0, -1, 0, 0.05]\n- [1, 0, 0, -0.02]\n- [0, 0, 1, 0.1]\n"
        "- [0, 0, 0, 1]\n");
  write(yaml / "ur_pose.txt", "p[0.4, -0.1, 0.3, 0.0, 3.1415927, 0.0]\n");
  write(json / "matrix.json", "[[0, -1, 0, 0.05], [1, 0, 0, -0.02], [0, 0, 1, 0.1], [0, 0, 0, 1]]");
  write(json / "easy_handeye.json",
        R"({"eye_on_hand": false, "transformation": {"x": 1, "y": 0, "z": 0.5, "qx": 0,)"
        R"( "qy": 0, "qz": 0, "qw": 1}})");
  write(json / "keyed.json", R"({"position": {"x": 0, "y": 0, "z": 0.1},)"
                             R"( "quaternion_wxyz": [1, 0, 0, 0]})");
}

void manifest_seeds(const fs::path& dir) {
  write(dir / "night.csv",
        "scan,flange_pose,hand_eye,viewpoint\n"
        "cell1/a.pcd,poses/a.yaml,he.yaml,\"0.1 0.2 0.3\"\n\n"
        "cell1/a.ply,,,\ncell2/\"q\"\"uoted\".pcd,poses/b.json,,\n");
  write(dir / "scans.csv", "viewpoint,scan\n,x.pcd\r\n\"0 0 -1\",sub/x.pcd\r\n");
}

// A depth PNG (read with depth_seed_intrinsics.json, written beside the seed folders) and
// intrinsics JSON in RealSense's spellings.
void depth_seeds(const fs::path& png, const fs::path& json, const fs::path& out) {
  write(png / "small.png", groovetrace::fuzz::small_depth_png());
  write(out / "depth_seed_intrinsics.json",
        R"({"fx": 60, "fy": 55, "ppx": 3.5, "ppy": 2.5, "depth_scale": 0.001})");
  write(json / "plain.json",
        R"({"fx": 60, "fy": 55, "ppx": 3.5, "ppy": 2.5, "depth_scale": 0.001})");
  write(json / "realsense.json",
        R"({"width": 8, "height": 6, "ppx": 3.5, "ppy": 2.5, "fx": 60.1, "fy": 59.9,)"
        R"( "model": "distortion.brown_conrady", "coeffs": [0, 0, 0, 0, 0], "depth_scale": 1e-4})");
}

// libFuzzer dictionaries: the words each format is made of.
void dictionaries(const fs::path& dir) {
  auto dict = [&](const char* name, const std::vector<std::string>& words) {
    std::string text;
    for (const auto& w : words) text += "\"" + w + "\"\n";
    write(dir / name, text);
  };
  dict("pcd.dict",
       {"VERSION", "FIELDS", "COLUMNS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT",
        "POINTS", "DATA", "ascii", "binary", "binary_compressed", "nan", "inf", "\\x0a"});
  dict("ply.dict", {"ply",
                    "format",
                    "ascii",
                    "binary_little_endian",
                    "binary_big_endian",
                    "element",
                    "property",
                    "list",
                    "vertex",
                    "face",
                    "range_grid",
                    "camera",
                    "obj_info",
                    "num_cols",
                    "num_rows",
                    "end_header",
                    "uchar",
                    "float",
                    "double",
                    "int",
                    "\\x0a"});
  std::vector<std::string> keys;
  for (const auto& spec : groovetrace::param_specs()) keys.push_back(spec.key);
  for (const char* w : {"robust", "paper", "auto", "cpu", "opencl", "mm", "m", "true", "null"}) {
    keys.emplace_back(w);
  }
  dict("config.dict", keys);
  dict("calibration.dict", {"translation",
                            "rotation",
                            "[",
                            "]",
                            "{",
                            "}",
                            ": ",
                            "1e308",
                            "transformation",
                            "transform",
                            "parameters",
                            "eye_on_hand",
                            "calibration_type",
                            "eye_in_hand",
                            "qx",
                            "qw",
                            "position",
                            "orientation",
                            "quaternion",
                            "_xyzw",
                            "_wxyz",
                            "pose",
                            "p[",
                            "%YAML:1.0\\x0a",
                            "!!opencv-matrix",
                            "rows",
                            "cols",
                            "dt",
                            "data",
                            "R_cam2gripper",
                            "t_cam2gripper",
                            "<opencv_storage>",
                            "</opencv_storage>",
                            "type_id=\\\"opencv-matrix\\\"",
                            "<!--",
                            "-->",
                            "&amp;",
                            "\\x0a"});
  dict("depth.dict", {"IHDR", "IDAT", "IEND", "fx", "fy", "ppx", "ppy", "depth_scale", "width",
                      "height", "model", "coeffs", "brown_conrady", "none", "distortion."});
  dict("manifest.dict",
       {"scan", "flange_pose", "hand_eye", "viewpoint", ".pcd", ".ply", "..", "/", "\\\"", ","});
}

// Each seed through the reader its harness calls.
bool read_back(const fs::path& seeds) {
  const std::vector<std::pair<std::string, std::function<void(const std::string&)>>> readers = {
      {"pcd", [](const std::string& p) { groovetrace::read_cloud(p); }},
      {"ply", [](const std::string& p) { groovetrace::read_cloud(p); }},
      {"config_yaml",
       [](const std::string& p) {
         groovetrace::Params params;
         groovetrace::apply_config_file(params, p);
       }},
      {"config_json",
       [](const std::string& p) {
         groovetrace::Params params;
         groovetrace::apply_config_file(params, p);
       }},
      {"calibration_yaml", [](const std::string& p) { groovetrace::read_transform(p); }},
      {"calibration_json", [](const std::string& p) { groovetrace::read_transform(p); }},
      {"manifest", [](const std::string& p) { groovetrace::batch::list_jobs({p}); }},
      {"depth_png",
       [&seeds](const std::string& p) {
         groovetrace::ReadOptions o;
         o.intrinsics_path = (seeds.parent_path() / "depth_seed_intrinsics.json").string();
         o.min_valid_points = 1;
         groovetrace::read_cloud(p, o);
       }},
      {"depth_intrinsics", [](const std::string& p) {
         groovetrace::io::parse_depth_intrinsics(groovetrace::io::read_all(p), p);
       }}};
  bool ok = true;
  for (const auto& [name, read] : readers) {
    for (const auto& entry : fs::directory_iterator(seeds / name)) {
      try {
        read(entry.path().string());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "fuzz_seeds: seed %s is refused: %s\n", entry.path().c_str(),
                     e.what());
        ok = false;
      }
    }
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_seeds OUTDIR\n");
    return 2;
  }
  const fs::path out(argv[1]);
  pcd_seeds(out / "seeds" / "pcd");
  ply_seeds(out / "seeds" / "ply");
  config_seeds(out / "seeds" / "config_yaml", out / "seeds" / "config_json");
  calibration_seeds(out / "seeds" / "calibration_yaml", out / "seeds" / "calibration_json");
  manifest_seeds(out / "seeds" / "manifest");
  depth_seeds(out / "seeds" / "depth_png", out / "seeds" / "depth_intrinsics", out);
  dictionaries(out / "dicts");
  return read_back(out / "seeds") ? 0 : 1;
}
