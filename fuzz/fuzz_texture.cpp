// fuzz_texture: libFuzzer target for texture images (PNG, JPEG, BMP, TGA via stb_image) through load_texture.
// Input layout: see feed_texture in fuzz_entry.h. Corpus: fuzz/corpus/texture/.
#include "fuzz_main.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return bl::fuzz::run_one(bl::fuzz::target::texture, data, size);
}
