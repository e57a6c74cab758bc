// cli: the command line of SPEC.md section 4 (render, diff, compare), parsed with CLI11.
#pragma once

namespace bl {

// Runs the command line; returns the process exit status (0, 1, 2, 3, 130, 143).
int run_cli(int argc, char** argv);

}  // namespace bl
