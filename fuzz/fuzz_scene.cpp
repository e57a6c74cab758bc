// fuzz_scene: libFuzzer target for scene files (JSON) through load_scene_desc.
// Input layout: see feed_scene in fuzz_entry.h. Corpus: fuzz/corpus/scene/.
#include "fuzz_main.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return bl::fuzz::run_one(bl::fuzz::target::scene, data, size);
}
