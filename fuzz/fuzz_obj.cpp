// fuzz_obj: libFuzzer target for OBJ + MTL text (split at a line "#=mtl") through load_obj.
// Input layout: see feed_obj in fuzz_entry.h. Corpus: fuzz/corpus/obj/.
#include "fuzz_main.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return bl::fuzz::run_one(bl::fuzz::target::obj, data, size);
}
