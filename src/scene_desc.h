// scene_desc: the scene file of SPEC.md section 3 (JSON) or a bare OBJ, parsed into plain parameters.
// Invariants: every value is validated (finite, in range) and every unknown key is an error, so a typo
// can never silently change a render; defaults are those of a bare OBJ. Paths are resolved to be usable
// from the current directory.
#pragma once

#include "math.h"

#include <cstdint>
#include <string>

namespace bl {

// Pinhole camera placement; `automatic` means "frame the mesh bounds from +z" (neither eye nor target in the file).
// With only one of them given, the other comes from that framing: a missing target is the bounds' centre, a
// missing eye lies on the +z side of the target at the framing distance.
struct camera_params {
  bool automatic = true;
  bool frame_eye = false, frame_target = false;
  vec3f eye = {0, 0, 1}, target = {0, 0, 0}, up = {0, 1, 0};
  float fov_y_deg = 45;
  bool up_given = false;
  int eye_line = 0, target_line = 0, up_line = 0, camera_line = 0;  // in the scene file (0: not there), for messages
};

// A distant disk light. direction points from the scene toward the sun (unit length after parsing).
struct sun_params {
  bool enabled = false;
  bool animated = false;            // direction_end given (render --frames moves the sun to it)
  vec3f direction_end = {0, 1, 0};  // unit, the direction at the last frame of an animation
  vec3f direction = {0, 1, 0};
  vec3f irradiance = {0, 0, 0};
  float angular_diameter_deg = 0.53f;
};
// 1 - cos of the half-angle of a sun disk of this diameter, without cancellation. A disk smaller than a half-angle of
// 1e-6 rad (0.2 arc seconds) is drawn at that size: its irradiance is the same, and its radiance and pdf stay in
// float's range (a diameter of 1e-18 degrees would overflow both).
float sun_one_minus_cos(float angular_diameter_deg);

// Everything a scene file says.
struct scene_desc {
  std::string path;       // the scene file itself (for messages)
  std::string mesh_path;  // OBJ, resolved relative to the scene file
  camera_params camera;
  int width = 640, height = 480;
  int spp = 64, max_depth = 5;
  uint64_t seed = 0;
  sun_params sun;
  bool two_sided_emitters = false;
};

// Reads a .json scene file or wraps a bare .obj; throws input_error naming the file (and line) on problems.
scene_desc load_scene_desc(const std::string& path);

// The sun direction of frame `frame` of `frames`, as a scene file would state it: the unit direction a fraction
// frame / (frames - 1) of the way along the great circle from direction to direction_end. (Rendering the frame
// applies the same normalisation as loading that scene file, so both give the same image.)
vec3f animated_sun_direction(const sun_params& sun, int frame, int frames);

// The camera of a bare OBJ: looks at the centre of `bounds` from the +z side, whole box in view.
camera_params frame_bounds(const bbox3f& bounds, float fov_y_deg, float aspect);

}  // namespace bl
