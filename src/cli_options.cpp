// cli_options: the commands' options, their help texts, checks and groups (see cli_options.h).
#include "cli_options.h"

#include "cli_validators.h"
#include "light_sampler.h"

#include <cerrno>
#include <climits>
#include <cstdlib>

namespace bl {

namespace {

// The options `render`, `profile` and `compare` share: spp or time, size, depth, threads, seed, quiet, sampler options.
void add_render_options(CLI::App* r, render_options& o) {
  auto* spp = r->add_option("--spp", o.spp, "Samples per pixel (default: the scene's render.spp)")
                  ->check(CLI::Range(1, INT_MAX));
  auto* time = r->add_option("--time", o.time,
                             "Render passes until this many seconds are spent (the last one cut to the spp that fit "
                             "the time left, so a render ends near it)")
                   ->check(CLI::Range(1e-6, 1e9))->check(finite_number);
  spp->excludes(time);
  r->add_option("--max-depth", o.max_depth,
                "Path length in segments; 1 = direct illumination only (camera ray, NEE and emission seen; a sharp "
                "glossy lobe then sees lamps through light samples alone, noisily: see README), 2 adds one bounce "
                "(default: the scene's render.max_depth)")
      ->check(CLI::Range(1, 1000));
  r->add_option("--light-samples", o.light_samples,
                "NEE samples at every path vertex, each its own light, point and shadow ray, averaged (default 1)")
      ->check(CLI::Range(1, 64));
  r->add_option_function<std::string>(
      "--light-points",
      [&o](const std::string& s) {
        if (s == "auto") {
          o.light_points = 0;
          return;
        }
        char* end = nullptr;
        long v = s.empty() || s[0] < '0' || s[0] > '9' ? 0 : std::strtol(s.c_str(), &end, 10);
        if (end == nullptr || *end != '\0' || v < 1 || v > 64)
          throw CLI::ValidationError("--light-points", "must be auto or an integer from 1 to 64 (got " + s + ")");
        o.light_points = int(v);
      },
      "Points (1 to 64) on the light a first-vertex NEE draw chose, each with its shadow ray, averaged: they cut the "
      "noise inside that light (a lamp half hidden by leaves) for less than whole samples would cost. auto: 2 for the "
      "first 8 spp, then 1, 2, 3, 5 or 8 per 8x8-pixel tile, chosen between passes from the noise and the cost (in "
      "path vertices) each tile measured, for the least error times cost over the image (default auto)")
      ->type_name("auto|N");
  r->add_option("--threads", o.threads, "Worker threads (default: all cores); never changes the image")
      ->check(CLI::Range(1, 4096));
  r->add_option_function<std::string>(
      "--seed",
      [&o](const std::string& s) {
        // Digits only, within 64 bits (a conversion would wrap "-1" and saturate 2^64 without a word).
        errno = 0;
        char* end = nullptr;
        unsigned long long v = s.empty() || s[0] < '0' || s[0] > '9' ? 0 : std::strtoull(s.c_str(), &end, 10);
        if (end == nullptr || *end != '\0' || errno == ERANGE)
          throw CLI::ValidationError("--seed", "must be an integer from 0 to 18446744073709551615 (got " + s + ")");
        o.seed = uint64_t(v), o.has_seed = true;
      },
      "Random seed, 0 to 2^64 - 1 (default: the scene's render.seed)")
      ->type_name("UINT");
  r->add_option("--width", o.width, "Image width in pixels (default: the scene's image.width; at most 2^28 pixels in all)")
      ->check(CLI::Range(1ll, max_side));
  r->add_option("--height", o.height, "Image height in pixels (default: the scene's image.height; at most 2^28 pixels in all)")
      ->check(CLI::Range(1ll, max_side));
  r->add_flag("--quiet", o.quiet, "No progress bar, notes of slow phases or summary");
  r->add_option("--pass-weighting", o.pass_weighting,
                "Adaptive samplers (bayes, donikian): a pass after n spp counts (n+1)/(n+1+S) per sample, so the first "
                "passes, taken before much is learned, weigh less; in a direct render bayes's first 8 spp count "
                "(n+1)/(n+1+4S), and where its check found learning to pay by then, its later passes (n+1)/(n+1+16S) "
                "among themselves, their share of the image that of S; after bayes falls back to power (or bvh) "
                "sampling, the later passes (one stratified set) weigh alike among themselves, their share of the image "
                "that of (n+1)/(n+1+S); no weight or share depends on the samples it weighs, so the image stays "
                "unbiased (default 4; 0: all samples alike)")
      ->check(CLI::Range(0.0, 1e9))->check(finite_number);
  r->add_flag("--independent-samples", o.independent,
              "Independent random light choices, light points and BSDF directions at the first hit (default: "
              "stratified over each pixel's samples; the light choice and point of the adaptive samplers over the "
              "samples since their model last changed, the points of --light-points auto over each light's draws in a "
              "pass)");
  // Regions, cuts and the ablation switches of the adaptive samplers.
  const char* grp = region_group;
  r->add_option("--grid", o.regions.grid,
                "Region cells along the shortest axis of the scene bounds (default 64; bayes in images under 320x240 "
                "pixels: 64 * sqrt(pixels / 76800), rounded, at least 16)")
      ->check(CLI::Range(1, 100000))->group(grp);
  r->add_option("--max-cut", o.regions.max_cut, "Light clusters per region (default 64, at most 1024)")
      ->check(CLI::Range(1, 1024))->group(grp);
  r->add_option("--cut-coherence", o.regions.coherence,
                "Keep a light cluster whole when its radius / gap to the region <= this (default 0.25; 0 = off)")
      ->check(CLI::Range(0.0, 100.0))->check(finite_number)->group(grp);
  r->add_option("--cut-members", o.regions.max_members,
                "bayes: clusters of a region's cut are refined into at most this many members in all, each learned "
                "apart and chosen inside its cluster (default 128 with --max-depth 1, else 0; at most 1024). Any count "
                "also lets a fine cluster learn from the coarse cluster holding it (0: only from one of the same "
                "node), so a count that refines nothing (at most the cut size) can still differ a little from 0")
      ->check(CLI::Range(0, 1024))->group(grp);
  r->add_option("--shared-cut-lights", o.regions.shared_cut_lights,
                "Scenes with at most this many lights, and at most --max-cut, give every region a cut of all lights, "
                "no clustering (default 16; 0: always clustered cuts)")
      ->check(CLI::Range(0, 1 << 30))->group(grp);
  r->add_option("--fine-depth", o.regions.fine_depth,
                "Path vertices up to this depth use fine regions, deeper ones coarse regions (default 1)")
      ->check(CLI::Range(1, 1000))->group(grp);
  r->add_option("--region-min-samples", o.regions.min_samples,
                "NEE samples a fine cell asks for before it gets its own region (default 16; the cells that "
                "pixel-centre camera rays reach get theirs before the first pass)")
      ->check(CLI::Range(1, 1 << 30))->group(grp);
  r->add_option("--region-min-pixels", o.regions.min_pixels,
                "bayes: a first hit uses its fine cell's region only where the cell's side squared is at least this "
                "many times its pixel's footprint on the surface (distance^2 x the pixel's solid angle / cos), else "
                "the coarse region: a smaller cell gets under this share of a pixel's samples per spp (default "
                "0.125; 0: always the fine cell)")
      ->check(CLI::Range(0.0, 1e6))->group(grp);
  r->add_option("--region-budget", o.regions.max_pairs,
                "Most (region, cluster) pairs before coarser regions serve (default: bayes 32 per pixel of the "
                "image, at most 1572864; the others 1572864; at most 2^29)")
      // Pair offsets are int: fine and coarse pairs (each up to the budget) must stay below 2^31.
      ->check(CLI::Range(int64_t(1), int64_t(1) << 29))->group(grp);
  const char* bg = bayes_group;
  r->add_option("--bayes-pmf", o.bayes_pmf,
                "second-moment (the paper; default) or mean (ablation: PMF from the mean only)")
      ->check(CLI::IsMember({"second-moment", "mean"}))->group(bg);
  r->add_option("--bayes-prior", o.bayes_prior,
                "region (default: prior mean per region and cluster, a point only scales it by 1/d^2) or point "
                "(ablation: prior mean from the bound at every shading point)")
      ->check(CLI::IsMember({"region", "point"}))->group(bg);
  r->add_flag_callback("--bayes-no-cv", [&o] { o.bayes.control_variate = false; },
                       "Ablation: no control variates (with the region prior they apply at diffuse points: NEE of a "
                       "light they cover is unweighted, no MIS with BSDF sampling)")->group(bg);
  r->add_flag_callback("--bayes-cv-last-only", [&o] { o.bayes.cv_every_vertex = false; },
                       "Ablation: control variates only where NEE is unweighted anyway (direct illumination, a path's "
                       "last vertex), MIS for every light at the other vertices (the rule before 0.56)")->group(bg);
  r->add_option("--bayes-cv-min-visible", o.bayes.cv_min_visible,
                "Control variates only for lamp clusters a region sees with probability at least this (default 0: "
                "any) and that have samples there or in its coarse region (their mean is capped by those samples' "
                "mean)")
      ->check(CLI::Range(0.0, 1.0))->check(finite_number)->group(bg);
  r->add_option("--bayes-cv-sun-min-visible", o.bayes.cv_sun_min_visible,
                "The same for the sun (default 0.96: its sharp shadow edges made control variates at lower "
                "visibility fireflies in the dark pixels beside them)")
      ->check(CLI::Range(0.0, 1.0))->check(finite_number)->group(bg);
  r->add_flag_callback("--bayes-no-orientation", [&o] { o.bayes.orientation = false; },
                       "Ablation: a point scales a cluster's weight by 1/d^2 only, not also by the receiver cosine bound")
      ->group(bg);
  r->add_flag_callback("--bayes-no-bsdf-factor", [&o] { o.bayes.bsdf_factor = false; },
                       "Ablation: a glossy point weighs clusters as a diffuse one would (no Phong lobe in its factor)")
      ->group(bg);
  r->add_flag_callback("--bayes-no-regression", [&o] { o.bayes.distance_regression = false; },
                       "Ablation: no 1/d^2 distance regression (z = Y): near lamps' spread then starves what a region "
                       "rarely sees lit (the living room's sun through its windows): unbiased, but heavy-tailed images, "
                       "mostly too dark at practical spp")->group(bg);
  r->add_flag_callback("--bayes-naive", [&o] { o.bayes.prior = false; },
                       "Ablation: no Bayesian prior, plug-in sample moments (the naive adaptive method: clusters it starves are "
                       "never sampled again, so its images are biased in practice)")->group(bg);
  r->add_option("--bayes-unseen-cap", o.bayes.unseen_cap,
                "A cluster none of whose lights has given a region a non-zero sample in this many samples (its coarse "
                "region's counted with it) weighs at a point at most the heaviest cluster there that has: its "
                "prior, the bound, would keep a lamp far brighter than the others but shut away (in a box, the sun "
                "outside a closed room) taking most samples for ever (default 8; 0: off, the paper's weights)")
      ->check(CLI::Range(0.0, 1e9))->check(finite_number)->group(bg);
  r->add_option("--bayes-epsilon", o.bayes.epsilon, "Defensive mixing with the prior-only (bound) PMF, in [0, 1] (default 0)")
      ->check(CLI::Range(0.0, 1.0))->check(finite_number)->group(bg);
  // (At most 1e6 apart from the counts: the posterior mean of 1 - p0 stays far above float's least number.)
  r->add_option("--bayes-a0", o.bayes.a0,
                "Beta prior of p0: pseudo-count of zero samples (1e-6 to 1e6, default 0.3; a large a0, or a tiny b0, "
                "starves clusters before their first lit sample: heavy-tailed images, mostly too dark)")
      ->check(CLI::Range(1e-6, 1e6))->check(finite_number)->group(bg);
  r->add_option("--bayes-b0", o.bayes.b0,
                "Beta prior of p0: pseudo-count of non-zero samples (1e-6 to 1e6, default 0.03)")
      ->check(CLI::Range(1e-6, 1e6))->check(finite_number)->group(bg);
  // (kappa0 and c at most 1e6: beyond, kappa0 n1 and c mu0^2 of bright lights overflow, and every weight met the
  // ceiling of the fold, max_pair_weight, so that the PMF ignored the bound and p0 alike.)
  r->add_option("--bayes-kappa0", o.bayes.kappa0, "Prior pseudo-count of the mean k (1e-6 to 1e6, default 1)")
      ->check(CLI::Range(1e-6, 1e6))->check(finite_number)->group(bg);
  r->add_option("--bayes-alpha0", o.bayes.alpha0, "Inverse-gamma shape of the variance h (1.000001 to 1e9, default 2)")
      ->check(CLI::Range(1.000001, 1e9).description("FLOAT in [1.000001 - 1e+09]"))->check(finite_number)->group(bg);
  r->add_option("--bayes-oracle", o.bayes.oracle_spp,
                "Oracle mode: learn for this many spp first (own seed, not timed), then freeze the statistics "
                "(default 0: off)")
      ->check(CLI::Range(0, 1 << 30))->group(bg);
  r->add_option("--bayes-hierarchy", o.bayes.hierarchy,
                "Concentration of a fine region's Beta prior on p0, centred on its coarse parent's posterior (0 = off, default 1)")
      ->check(CLI::Range(0.0, 1e9))->check(finite_number)->group(bg);
  r->add_flag_callback("--bayes-no-mean-hierarchy", [&o] { o.bayes.mean_hierarchy = false; },
                       "Ablation: a fine region's prior mean is its own bound only, not also capped by its coarse region's "
                       "posterior mean")->group(bg);
  r->add_option("--bayes-fallback-ratio", o.bayes.fallback_ratio,
                "Fall back to power sampling for the rest of the render when its estimated relMSE per sample is below "
                "this many times the learned sampler's in two checked passes in a row (from 4 spp on): where learning "
                "cannot pay for its own cost (default 1.5; doubled unless --independent-samples, as the estimate "
                "assumes independent samples and stratification helps power sampling more: path traced, only as far "
                "as the first vertex's share of the estimate goes; 0 = never)")
      ->check(CLI::Range(0.0, 1e9))->check(finite_number)->group(bg);
  r->add_option("--bayes-bvh-fallback-ratio", o.bayes.fallback_bvh_ratio,
                "The same check falls back to the bvh sampler instead where its estimated relMSE per sample is below "
                "this many times the learned sampler's (no factor for stratification) and power's is not below its "
                "own threshold: many lights every point sees alike, in clusters learning cannot split (default 1; 0 = "
                "never; off with --bayes-fallback-ratio 0)")
      ->check(CLI::Range(0.0, 1e9))->check(finite_number)->group(bg);
  r->add_option("--bayes-early-draws", o.bayes.early_draws,
                "Direct illumination: NEE draws per camera sample (at least --light-samples) in the first "
                "--bayes-early-spp spp, while the model learns most: those passes weigh little in the image, and a "
                "draw costs less than the camera ray it shares (default 4; 1 = off)")
      ->check(CLI::Range(1, 64))->group(bg);
  r->add_option("--bayes-early-spp", o.bayes.early_spp,
                "Direct illumination: passes that start before this many spp take --bayes-early-draws (default 16; "
                "0 = off)")
      ->check(CLI::Range(0, 1 << 30))->group(bg);
  r->add_option("--bayes-c", o.bayes.c,
                "Prior squared coefficient of variation: beta0 = c mu0^2 (alpha0 - 1) (1e-6 to 1e6, default 0.3)")
      ->check(CLI::Range(1e-6, 1e6))->check(finite_number)->group(bg);
}

}  // namespace

void add_render_command(CLI::App& app, render_options& o) {
  CLI::App* r = app.add_subcommand("render", "Render a scene (.json scene file or bare .obj)");
  r->add_option("SCENE", o.scene, "Scene file (.json) or mesh (.obj)")->required()->type_name("FILE");
  r->add_option("--sampler", o.sampler, "Light selection for NEE: " + sampler_names() + " (default bayes)")
      ->type_name("NAME");
  // One file per -o (a vector option would otherwise also take the scene after it: `render -o a.exr SCENE`).
  r->add_option("-o,--output", o.outputs,
                ".exr/.pfm (linear float RGB) or .png (8-bit sRGB, clamped); repeatable, one file each (default: "
                "SCENE's name with .exr for its extension, in the current directory: scene.json gives scene.exr)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->type_name("FILE");
  r->add_option("--reference", o.reference,
                "Reference .exr/.pfm of the same size: error after every pass (in --log), the final one in the "
                "summary line")
      ->type_name("FILE")->check(file_name);
  r->add_option("--log", o.log,
                "Per-pass CSV: sampler,pass,spp,seconds,relmse,mse (relmse and mse empty without --reference)")
      ->type_name("FILE")->check(file_name);
  r->add_option("--frames", o.frames,
                "Render an animation of N frames: the sun moves from sun.direction to sun.direction_end; -o, --log "
                "and --reference then take a frame pattern such as out_%04d.exr (default output: SCENE's name with "
                "_%04d.exr, e.g. scene_0000.exr; without --frames names are literal; with --checkpoint, --resume "
                "continues at the frame under way)")
      ->check(CLI::Range(1, 100000));
  r->add_option("--checkpoint", o.checkpoint,
                "Save the render state to FILE between passes (at most every --checkpoint-every s, on SIGINT/SIGTERM, "
                "and at the end); --resume continues it")
      ->type_name("FILE")->check(file_name);
  r->add_option("--checkpoint-every", o.checkpoint_every, "Seconds between checkpoints (default 30; 0: every pass)")
      ->check(CLI::Range(0.0, 1e9))->check(finite_number);
  r->add_option("--resume", o.resume,
                "Continue the render saved in FILE (same scene and options; --spp may be larger: the same bytes as one render "
                "of that many spp when the saved spp ended a scheduled pass, e.g. 8 10 12 15 18 22 27 33 ...); its spp, "
                "seconds and --time budget count the saved ones")
      ->type_name("FILE")->check(file_name);
  r->add_flag("--signal-after-last-pass", o.signal_after_last_pass,
              "testing: raise SIGINT once the last pass is done, before the outputs are written")
      ->group("");
  r->add_option("--stop-after-passes", o.stop_after_passes, "testing: raise SIGINT after N passes, counted over frames (0: during set-up)")
      ->group("");
  r->add_option("--signals-in-first-pass", o.signals_in_first_pass,
                "testing: raise SIGINT N times once the first pass's first row is done (-N: 0.6 s apart)")
      ->group("");
  r->add_option("--signals-in-setup", o.signals_in_setup,
                "testing: raise SIGINT N times while the render sets up (-N: 0.6 s apart)")
      ->group("");
  r->add_option("--signal-in-frame", o.signal_frame, "testing: raise SIGINT once during frame K's first pass (K > 0)")
      ->group("");
  r->add_option("--kill-after-passes", o.kill_after_passes, "testing: raise SIGKILL after the checkpoint of pass N, counted over frames")
      ->group("");
  r->add_option("--frame-decay", o.frame_decay,
                "Animations: learned statistics are scaled by this at each new frame (default 0.5; 1 keeps all)")
      ->check(CLI::Range(0.0, 1.0))->check(finite_number);
  add_render_options(r, o);
}

// ---- profile: where the time of a render goes ----

void add_profile_command(CLI::App& app, render_options& o) {
  CLI::App* p = app.add_subcommand("profile", "Time the stages of a render (ns per NEE sample) against the raw "
                                              "Embree shadow-ray limit on the same scene");
  p->add_option("SCENE", o.scene, "Scene file (.json) or mesh (.obj)")->required()->type_name("FILE");
  p->add_option("--sampler", o.sampler, "Light selection for NEE: " + sampler_names() + " (default bayes)")
      ->type_name("NAME");
  add_render_options(p, o);
}

// ---- compare: equal-time (or equal-spp) comparison of samplers (compare.h does the work) ----

void add_compare_command(CLI::App& app, compare_options& o) {
  CLI::App* c = app.add_subcommand("compare", "Render several samplers for the same time (or spp) against a "
                                              "reference: curves.csv, error_vs_time.svg, summary.md, images");
  c->add_option("SCENE", o.render.scene, "Scene file (.json) or mesh (.obj)")->required()->type_name("FILE");
  c->add_option("--reference", o.render.reference, "Reference .exr/.pfm of the render's size")
      ->required()
      ->type_name("FILE")
      ->check(file_name);
  // (One string, split here: a vector option would show as "TEXT ..." in the help, as if it took several words.)
  c->add_option("--samplers", o.samplers, "Comma-separated samplers, the first is the baseline: " + sampler_names())
      ->required()->type_name("NAME,NAME,...");
  c->add_option("--out", o.out, "Output directory (created if missing)")
      ->required()->type_name("DIR")->check(file_name);
  c->add_option("--runs", o.runs, "Runs per sampler, seeds base, base+1, ... (default 1)")->check(CLI::Range(1, 10000));
  c->add_option("--reference-note", o.reference_note, "How the reference was made, for summary.md");
  add_render_options(c, o.render);
  // (compare has no scene default: every sampler renders the same given budget)
  c->get_option("--spp")->description("Samples per pixel of every render (this or --time is required)");
  c->get_option("--time")->description("Seconds per render, the last pass cut to the time left (this or --spp is required)");
}

}  // namespace bl
