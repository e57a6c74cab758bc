// cli_validators: the command line's value checks (cli_validators.h).
#include "cli_validators.h"

#include <cmath>
#include <cstdlib>
#include <string>

namespace bl {

// Rejects NaN and infinities: CLI::Range and CLI::PositiveNumber let NaN through (every comparison with it is false).
// (decimal_number refuses "nan" and "inf" as text; this also catches a decimal that overflows, such as 1e400.)
const CLI::Validator finite_number(
    [](std::string& text) -> std::string {
      char* end = nullptr;
      double v = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || !std::isfinite(v)) return "Value " + text + " is not a finite number";
      return {};
    },
    "");

// A file name that is not empty: an empty shell variable (--log "$LOG") would otherwise drop the option silently.
const CLI::Validator file_name(
    [](std::string& text) -> std::string { return text.empty() ? "an empty file name" : std::string(); }, "");

// Integers on the command line are decimal: CLI11 reads "064" as octal 52 and "0x10" as hex, so that a zero-padded
// --spp silently rendered another count. Leading zeros are dropped ("064" is 64); a sign other than '-' (which
// the ranges then refuse), a base prefix, spaces or a fraction are refused.
const CLI::Validator decimal_integer(
    [](std::string& text) -> std::string {
      size_t digits = text.size() > 1 && text[0] == '-' ? 1 : 0;
      if (digits == text.size() ||
          text.find_first_not_of("0123456789", digits) != std::string::npos)
        return "Value " + text + " is not a decimal integer";
      size_t first = text.find_first_not_of('0', digits);
      text.erase(digits, (first == std::string::npos ? text.size() - 1 : first) - digits);
      return {};
    },
    "");

// Decimal numbers likewise: strtod also reads "0x10" (16), "+0.5", " 2" and "inf", and a value that is not a number at
// all ("1e", "0.5s") was reported as out of range. A plain decimal with an optional '-', fraction and exponent.
const CLI::Validator decimal_number(
    [](std::string& text) -> std::string {
      auto digits = [&](size_t i) {
        size_t j = i;
        while (j < text.size() && text[j] >= '0' && text[j] <= '9') j++;
        return j;
      };
      const size_t first = text.size() > 1 && text[0] == '-' ? 1 : 0;
      const size_t int_end = digits(first);
      size_t mantissa_end = int_end;
      if (mantissa_end < text.size() && text[mantissa_end] == '.') mantissa_end = digits(mantissa_end + 1);
      const bool mantissa = int_end > first || mantissa_end > int_end + 1;  // digits before or after the point
      size_t end = mantissa_end;
      if (mantissa && end < text.size() && (text[end] == 'e' || text[end] == 'E')) {
        size_t e = end + 1;
        if (e < text.size() && (text[e] == '-' || text[e] == '+')) e++;
        size_t e_end = digits(e);
        end = e_end > e ? e_end : std::string::npos;  // an exponent needs digits
      }
      if (!mantissa || end != text.size()) return "Value " + text + " is not a decimal number";
      // "-0" is 0: the checkpoint fingerprint compares the values' bits, and a resume with -0 refused its own 0.
      if (first == 1 && text.find_first_of("123456789", 1) >= mantissa_end) text.erase(0, 1);
      return {};
    },
    "");

}  // namespace bl
