// version: bayeslight --version, what a bug report needs (the checkpoint format says which checkpoints this binary
// resumes).
#pragma once

namespace bl {

// Prints the version, the checkpoint format and how the binary was built on stdout.
void print_version();

}  // namespace bl
