#!/usr/bin/python3
"""Writes the calibration golden files of tests/robot/test_frames.cpp (run once; the files are
committed). Every file holds the same transform T, computed here with numpy alone (not by
groovetrace): a rotation of ANGLE rad about AXIS (Rodrigues' formula) and the translation T.
The test builds the same transform from Eigen::AngleAxisd and compares to 1e-9."""
import numpy as np

AXIS = np.array([1.0, -2.0, 2.0]) / 3.0
ANGLE = 0.7
T = np.array([0.031, -0.012, 0.118])

K = np.array([[0, -AXIS[2], AXIS[1]], [AXIS[2], 0, -AXIS[0]], [-AXIS[1], AXIS[0], 0]])
R = np.eye(3) + np.sin(ANGLE) * K + (1 - np.cos(ANGLE)) * K @ K
q = np.concatenate([AXIS * np.sin(ANGLE / 2), [np.cos(ANGLE / 2)]])  # x, y, z, w
x, y, z, w = (repr(float(v)) for v in q)
tx, ty, tz = (repr(float(v)) for v in T)
r = AXIS * ANGLE
H = np.eye(4)
H[:3, :3] = R
H[:3, 3] = T


def write(name, text):
    with open(name, "w") as f:
        f.write(text)


write("groovetrace.yaml", f"# T_flange_camera\ntranslation: [{tx}, {ty}, {tz}]\n"
      f"rotation: [{x}, {y}, {z}, {w}]  # qx, qy, qz, qw\n")
write("groovetrace.json", f'{{"translation": [{tx}, {ty}, {tz}],\n "rotation": [{x}, {y}, {z}, {w}]}}\n')
# easy_handeye (ROS 1): yaml.dump of its dict, keys sorted.
write("easy_handeye.yaml", f"""parameters:
  eye_on_hand: true
  move_group: manipulator
  move_group_namespace: /
  namespace: /my_eye_on_hand/
  robot_base_frame: base_link
  robot_effector_frame: tool0
  tracking_base_frame: camera_color_optical_frame
  tracking_marker_frame: aruco_marker
transformation:
  qw: {w}
  qx: {x}
  qy: {y}
  qz: {z}
  x: {tx}
  y: {ty}
  z: {tz}
""")
# easy_handeye2 (ROS 2): message_to_yaml of a HandeyeCalibration message, a .calib file.
write("easy_handeye2.calib", f"""parameters:
  name: my_eih
  calibration_type: eye_in_hand
  robot_base_frame: base_link
  robot_effector_frame: tool0
  tracking_base_frame: camera_link
  tracking_marker_frame: marker
  freehand_robot_movement: true
  move_group_namespace: /
  move_group: manipulator
transform:
  translation:
    x: {tx}
    y: {ty}
    z: {tz}
  rotation:
    x: {x}
    y: {y}
    z: {z}
    w: {w}
""")
cv = lambda v: " ".join("%.16e" % e for e in v)
write("opencv.yaml", f"""%YAML:1.0
---
R_cam2gripper: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ {", ".join("%.16e" % e for e in R.flatten()[:4])},
       {", ".join("%.16e" % e for e in R.flatten()[4:])} ]
t_cam2gripper: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ {", ".join("%.16e" % e for e in T)} ]
""")
write("opencv.xml", f"""<?xml version="1.0"?>
<opencv_storage>
<!-- calibrateHandEye, Tsai -->
<R_cam2gripper type_id="opencv-matrix">
  <rows>3</rows>
  <cols>3</cols>
  <dt>d</dt>
  <data>
    {cv(R.flatten()[:4])}
    {cv(R.flatten()[4:])}</data></R_cam2gripper>
<t_cam2gripper type_id="opencv-matrix">
  <rows>3</rows>
  <cols>1</cols>
  <dt>d</dt>
  <data>
    {cv(T)}</data></t_cam2gripper>
<method>Tsai</method>
</opencv_storage>
""")
write("matrix.txt", "# T_flange_camera, rows\n" + "".join(" ".join(repr(float(e)) for e in row) + "\n" for row in H))
write("matrix.json", "[" + ",\n ".join("[" + ", ".join(repr(float(e)) for e in row) + "]" for row in H) + "]\n")
write("matrix.yaml", "".join("- [" + ", ".join(repr(float(e)) for e in row) + "]\n" for row in H))
write("ur_pose.txt", "p[" + ", ".join(repr(float(e)) for e in list(T) + list(r)) + "]\n")
write("ros_pose.yaml", f"""header:
  frame_id: tool0
pose:
  position: {{x: {tx}, y: {ty}, z: {tz}}}
  orientation: {{x: {x}, y: {y}, z: {z}, w: {w}}}
""")
write("quaternion_wxyz.json", f'{{"translation": [{tx}, {ty}, {tz}], "quaternion_wxyz": [{w}, {x}, {y}, {z}]}}\n')
