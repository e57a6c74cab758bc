// cli_validators: CLI11 validators for the command line's values (cli.cpp): finite numbers, non-empty file names,
// integers and numbers written in plain decimal.
#pragma once

#include <CLI/CLI.hpp>

namespace bl {

extern const CLI::Validator finite_number;    // refuses NaN, infinities and overflowing decimals
extern const CLI::Validator file_name;        // refuses an empty name
extern const CLI::Validator decimal_integer;  // a decimal integer (no octal, hex, sign '+', fraction); "064" is 64
extern const CLI::Validator decimal_number;   // a plain decimal number with an optional exponent; "-0" is 0

}  // namespace bl
