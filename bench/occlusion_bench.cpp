// occlusion_bench: the ray-casting limit of a scene — raw Embree rtcOccluded1 / rtcIntersect1 throughput on the
// renderer's own ray distribution (camera rays through jittered pixels; shadow rays from their first hits to
// points sampled uniformly on uniformly chosen lights), for comparison with the render's rays/s.
// Scene: BAYESLIGHT_BENCH_SCENE (default data/living_room/direct.json).
#include "bvh.h"
#include "camera.h"
#include "integrator.h"
#include "lights.h"
#include "rng.h"
#include "scene.h"
#include "scene_desc.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>
#include <vector>

namespace {

using namespace bl;

// A scene with a batch of camera rays and shadow rays.
struct ray_batch {
  scene_data scene;
  std::unique_ptr<bvh_data> bvh;
  light_data lights;
  std::vector<vec3f> cam_dir;
  vec3f eye;
  std::vector<vec3f> sh_org, sh_dir;
  std::vector<float> sh_tmax;
};

ray_batch& batch() {
  static ray_batch* b = [] {
    auto* r = new ray_batch;
    const char* env = std::getenv("BAYESLIGHT_BENCH_SCENE");
    std::string path = env ? env : std::string(BAYESLIGHT_SOURCE_DIR) + "/data/living_room/direct.json";
    scene_desc desc = load_scene_desc(path);
    int w = 320, h = 240;
    r->scene = build_scene(desc, float(w) / float(h));
    r->bvh = std::make_unique<bvh_data>(build_bvh(r->scene));
    r->lights = build_lights(r->scene);
    camera_data cam = make_camera(r->scene.camera, w, h);
    r->eye = cam.eye;
    render_inputs in;
    in.scene = &r->scene;
    in.bvh = r->bvh.get();
    in.lights = &r->lights;
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++) {
        vertex_randoms u = draw_vertex(sample_key(7, uint64_t(y * w + x), 0), 0);
        vec3f dir = camera_ray_dir(cam, float(x) + u.u[0], float(y) + u.u[1]);
        r->cam_dir.push_back(dir);
        hit_info hit = intersect(*r->bvh, cam.eye, dir);
        if (hit.tri == invalid_id || r->lights.count == 0) continue;
        surface_point sp = eval_surface(r->scene, hit.tri, hit.b1, hit.b2, dir);
        vertex_randoms v = draw_vertex(sample_key(7, uint64_t(y * w + x), 0), 1);
        int light = std::min(int(v.u[0] * float(r->lights.count)), r->lights.count - 1);
        light_sample ls = sample_light_point(r->lights, r->scene, light, sp.p, v.u[2], v.u[3]);
        if (!(ls.pdf > 0)) continue;
        shadow_ray sr = shadow_ray_of(r->scene, sp, ls);  // the render's own shadow rays
        if (!(sr.tmax > 0)) continue;
        r->sh_org.push_back(sr.org);
        r->sh_dir.push_back(sr.dir);
        r->sh_tmax.push_back(sr.tmax);
      }
    return r;
  }();
  return *b;
}

void BM_rtcOccluded1(benchmark::State& state) {
  ray_batch& b = batch();
  size_t n = b.sh_org.size(), i = size_t(state.thread_index()) * 7919 % n;
  int blocked = 0;
  for (auto _ : state) {
    blocked += occluded(*b.bvh, b.sh_org[i], b.sh_dir[i], b.sh_tmax[i]);
    if (++i == n) i = 0;
  }
  benchmark::DoNotOptimize(blocked);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_rtcOccluded1)->Threads(1)->Threads(2)->UseRealTime();

void BM_rtcIntersect1_camera(benchmark::State& state) {
  ray_batch& b = batch();
  size_t n = b.cam_dir.size(), i = size_t(state.thread_index()) * 7919 % n;
  int hits = 0;
  for (auto _ : state) {
    hits += intersect(*b.bvh, b.eye, b.cam_dir[i]).tri != invalid_id;
    if (++i == n) i = 0;
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_rtcIntersect1_camera)->Threads(1)->Threads(2)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
