// camera: a pinhole camera; raster coordinates have (0, 0) at the top-left corner of the image.
#pragma once

#include "math.h"
#include "scene_desc.h"

namespace bl {

// Camera basis scaled so that raster coordinates map straight to ray directions.
struct camera_data {
  vec3f eye;
  vec3f forward, right, up;  // right and up already scaled by the half-extent of the image plane at distance 1
  int width = 1, height = 1;
};

// The camera of `params` for an image of width x height pixels.
inline camera_data make_camera(const camera_params& params, int width, int height) {
  camera_data c;
  c.eye = params.eye;
  c.width = width;
  c.height = height;
  c.forward = normalize(params.target - params.eye);
  vec3f right = normalize(cross(c.forward, params.up));
  vec3f up = cross(right, c.forward);
  float tan_half = std::tan(0.5f * params.fov_y_deg * pi_f / 180.0f);
  float aspect = float(width) / float(height);
  c.right = right * (tan_half * aspect);
  c.up = up * tan_half;
  return c;
}

// Unit direction through raster point (x, y), x in [0, width), y in [0, height).
inline vec3f camera_ray_dir(const camera_data& c, float x, float y) {
  float sx = 2 * x / float(c.width) - 1;
  float sy = 1 - 2 * y / float(c.height);
  return normalize(c.forward + c.right * sx + c.up * sy);
}

// The side of a pixel's footprint on a surface at distance t whose geometric normal makes cosine cos_n with the ray:
// the square root of its area t^2 omega / cos_n, omega the solid angle of a pixel at the image's centre.
inline float pixel_footprint(const camera_data& c, float t, float cos_n) {
  float pixel = 2 * std::sqrt(dot(c.up, c.up)) / float(c.height);
  return t * pixel / std::sqrt(std::max(cos_n, 1e-4f));
}

}  // namespace bl
