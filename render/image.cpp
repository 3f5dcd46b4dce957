#include "render/image.h"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <system_error>

#include "io/atomic_file.h"

namespace shellmpm {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f) std::fclose(f);
  }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

[[noreturn]] void png_error_fn(png_structp png, png_const_charp msg) {
  auto* text = static_cast<std::string*>(png_get_error_ptr(png));
  *text = msg ? msg : "libpng error";
  png_longjmp(png, 1);
}
void png_warning_fn(png_structp, png_const_charp) {}

// libpng reports errors by longjmp: no C++ object with a destructor may be created in
// these two functions after setjmp; the pixel buffers live in the caller.
bool write_png_file(std::FILE* f, const std::uint8_t* pixels, int width, int height, int channels,
                    std::string* err) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, err, png_error_fn, png_warning_fn);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, f);
  png_set_compression_level(png, 6);
  png_set_filter(png, 0, PNG_FILTER_SUB);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               channels == 4 ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y)
    png_write_row(png, pixels + static_cast<std::size_t>(y) * width * channels);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

bool read_png_file(std::FILE* f, Image* out, std::string* err) {
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, err, png_error_fn, png_warning_fn);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, f);
  png_read_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  const int type = png_get_color_type(png, info), depth = png_get_bit_depth(png, info);
  if (depth != 8 || (type != PNG_COLOR_TYPE_RGB && type != PNG_COLOR_TYPE_RGBA) ||
      png_get_interlace_type(png, info) != PNG_INTERLACE_NONE) {
    *err = "not an 8-bit non-interlaced RGB or RGBA PNG";
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  if (type == PNG_COLOR_TYPE_RGB) png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
  png_read_update_info(png, info);
  out->width = static_cast<int>(w);
  out->height = static_cast<int>(h);
  out->rgba.assign(static_cast<std::size_t>(w) * h * 4, 0);
  for (png_uint_32 y = 0; y < h; ++y)
    png_read_row(png, out->pixel(0, static_cast<int>(y)), nullptr);
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

// 3x5 glyphs, one row per 3 bits (MSB = left column).
const unsigned char* glyph(char c) {
  static const unsigned char digits[10][5] = {
      {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7}, {5, 5, 7, 1, 1},
      {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1}, {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7}};
  static const unsigned char dash[5] = {0, 0, 7, 0, 0};
  static const unsigned char space[5] = {0, 0, 0, 0, 0};
  static const unsigned char F[5] = {7, 4, 6, 4, 4}, R[5] = {6, 5, 6, 5, 5}, A[5] = {2, 5, 7, 5, 5},
                             M[5] = {5, 7, 7, 5, 5}, E[5] = {7, 4, 6, 4, 7};
  if (c >= '0' && c <= '9') return digits[c - '0'];
  switch (c) {
    case '-':
      return dash;
    case 'F':
      return F;
    case 'R':
      return R;
    case 'A':
      return A;
    case 'M':
      return M;
    case 'E':
      return E;
    default:
      return space;
  }
}

void draw_label(Image& im, int x0, int y0, const std::string& text, int scale) {
  auto put = [&](int x, int y, std::uint8_t v) {
    if (x < 0 || y < 0 || x >= im.width || y >= im.height) return;
    std::uint8_t* p = im.pixel(x, y);
    p[0] = p[1] = p[2] = v;
    p[3] = 255;
  };
  for (int pass = 0; pass < 2; ++pass) {  // dark shadow, then white
    const int off = pass == 0 ? scale / 2 + 1 : 0;
    const std::uint8_t v = pass == 0 ? 20 : 255;
    for (std::size_t i = 0; i < text.size(); ++i) {
      const unsigned char* g = glyph(text[i]);
      for (int r = 0; r < 5; ++r)
        for (int c = 0; c < 3; ++c)
          if (g[r] & (4 >> c))
            for (int sy = 0; sy < scale; ++sy)
              for (int sx = 0; sx < scale; ++sx)
                put(x0 + static_cast<int>(i) * 4 * scale + c * scale + sx + off,
                    y0 + r * scale + sy + off, v);
    }
  }
}

}  // namespace

void write_png(const std::string& path, const Image& image, bool with_alpha) {
  if (image.width <= 0 || image.height <= 0)
    throw std::invalid_argument("write_png " + path + ": empty image");
  write_file_atomic(path, [&](const std::string& tmp) {
    FilePtr f(std::fopen(tmp.c_str(), "wb"));
    if (!f) throw std::system_error(errno, std::generic_category(), "cannot create " + tmp);
    const int channels = with_alpha ? 4 : 3;
    std::vector<std::uint8_t> px(static_cast<std::size_t>(image.width) * image.height * channels);
    for (std::size_t i = 0, n = static_cast<std::size_t>(image.width) * image.height; i < n; ++i)
      for (int c = 0; c < channels; ++c) px[i * channels + c] = image.rgba[i * 4 + c];
    std::string err;
    if (!write_png_file(f.get(), px.data(), image.width, image.height, channels, &err))
      throw std::runtime_error("writing PNG " + path + ": " + err);
    if (std::fflush(f.get()) != 0 || std::ferror(f.get()))
      throw std::system_error(errno, std::generic_category(), "writing " + tmp);
  });
}

Image read_png(const std::string& path) {
  FilePtr f(std::fopen(path.c_str(), "rb"));
  if (!f) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  unsigned char sig[8] = {};
  if (std::fread(sig, 1, 8, f.get()) != 8 || png_sig_cmp(sig, 0, 8) != 0)
    throw std::runtime_error(path + ": not a PNG file");
  std::rewind(f.get());
  Image im;
  std::string err;
  if (!read_png_file(f.get(), &im, &err)) throw std::runtime_error(path + ": " + err);
  return im;
}

Image downscale(const Image& in, int max_width) {
  if (in.width <= max_width) return in;
  const int w = max_width;
  const int h =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(in.height) * w / in.width)));
  Image out(w, h);
  for (int y = 0; y < h; ++y) {
    const int y0 = y * in.height / h, y1 = std::max(y0 + 1, (y + 1) * in.height / h);
    for (int x = 0; x < w; ++x) {
      const int x0 = x * in.width / w, x1 = std::max(x0 + 1, (x + 1) * in.width / w);
      unsigned sum[4] = {0, 0, 0, 0};
      for (int yy = y0; yy < y1; ++yy)
        for (int xx = x0; xx < x1; ++xx)
          for (int c = 0; c < 4; ++c) sum[c] += in.pixel(xx, yy)[c];
      const unsigned n = static_cast<unsigned>((y1 - y0) * (x1 - x0));
      for (int c = 0; c < 4; ++c)
        out.pixel(x, y)[c] = static_cast<std::uint8_t>((sum[c] + n / 2) / n);
    }
  }
  return out;
}

Image contact_sheet(const std::vector<Image>& tiles, const std::vector<std::string>& labels,
                    int columns) {
  if (tiles.empty()) return Image();
  const int tw = tiles[0].width, th = tiles[0].height, gap = 4;
  const int n = static_cast<int>(tiles.size());
  columns = std::max(1, std::min(columns, n));
  const int rows = (n + columns - 1) / columns;
  Image sheet(columns * tw + (columns + 1) * gap, rows * th + (rows + 1) * gap);
  for (std::size_t i = 0; i < sheet.rgba.size(); i += 4) {
    sheet.rgba[i] = sheet.rgba[i + 1] = sheet.rgba[i + 2] = 24;
    sheet.rgba[i + 3] = 255;
  }
  const int scale = std::max(1, th / 60);
  for (int i = 0; i < n; ++i) {
    const int ox = gap + (i % columns) * (tw + gap), oy = gap + (i / columns) * (th + gap);
    const Image& t = tiles[i];
    for (int y = 0; y < std::min(th, t.height); ++y)
      for (int x = 0; x < std::min(tw, t.width); ++x) {
        std::uint8_t* d = sheet.pixel(ox + x, oy + y);
        std::memcpy(d, t.pixel(x, y), 3);
        d[3] = 255;
      }
    if (i < static_cast<int>(labels.size()))
      draw_label(sheet, ox + 2 * scale, oy + th - 7 * scale, labels[i], scale);
  }
  return sheet;
}

}  // namespace shellmpm
