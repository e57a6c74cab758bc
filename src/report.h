// report: text outputs of a render — the per-pass CSV of SPEC.md section 6 and the one-line summary.
#pragma once

#include "render.h"

#include <string>
#include <vector>

namespace bl {

// CSV with header `sampler,pass,spp,seconds,relmse,mse` (error columns empty without a reference).
std::string pass_log_csv(const std::string& sampler, const std::vector<pass_record>& log);
// "rendered N spp in T s (P passes, R Mrays/s) -> files" for stderr.
std::string render_summary(const render_result& r, const std::vector<std::string>& outputs);
// Peak resident memory of this process so far (bytes; 0 when unknown).
size_t peak_memory_bytes();

// Tells stderr how many degenerate (zero-area) triangles the mesh at `mesh_path` lost on load, and the OBJ line of
// the first face that lost one (nothing when none).
void report_dropped_triangles(const std::string& mesh_path, int dropped, int first_line);

}  // namespace bl
