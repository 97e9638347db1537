// The browser build has no libpng (emscripten's ports cannot be fetched on
// these machines, see ENVIRONMENT.md). core/Image.cpp's PNG I/O is never used
// by the page (frames go to the canvas), but it must link: these four entry
// points of libpng's simplified API fail the way libpng reports failure, with
// a message saying why, so Image::readPng/writePng throw a readable error.
#include <png.h>

#include <cstring>

namespace {
void fail(png_imagep image) {
  image->warning_or_error = PNG_IMAGE_ERROR;
  std::strncpy(image->message, "PNG files are not available in the web viewer",
               sizeof image->message - 1);
  image->message[sizeof image->message - 1] = '\0';
}
}  // namespace

extern "C" {

int png_image_begin_read_from_file(png_imagep image, const char*) {
  fail(image);
  return 0;
}

int png_image_finish_read(png_imagep image, png_const_colorp, void*, png_int_32, void*) {
  fail(image);
  return 0;
}

int png_image_write_to_file(png_imagep image, const char*, int, const void*, png_int_32,
                            const void*) {
  fail(image);
  return 0;
}

void png_image_free(png_imagep) {}

}  // extern "C"
