// fuzz_image: libFuzzer target for the EXR / PFM reader (read_image: --reference and diff).
// Input layout: see feed_image in fuzz_entry.h. Corpus: fuzz/corpus/image/.
#include "fuzz_main.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return bl::fuzz::run_one(bl::fuzz::target::image, data, size);
}
