// third_party: the implementations of stb_image (+ stb_image_write) and tinyexr compiled from
// their Debian headers into the fuzz build only, so that the decoders the parsers call are instrumented for
// coverage and ASan/UBSan too (the Debian shared libraries the normal build links are opaque to both).
// Same versions and defaults as those libraries (tinyexr: zlib, no threads).
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image.h>
#include <stb_image_write.h>

#define TINYEXR_IMPLEMENTATION
#include <tinyexr.h>
