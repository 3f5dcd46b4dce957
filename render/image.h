// 8-bit RGBA images, PNG files (libpng, deterministic bytes) and contact sheets.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace shellmpm {

/// Rows from the top, RGBA interleaved; colour gamma-encoded, alpha = coverage by content
/// (0 where only the background shows).
struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(static_cast<std::size_t>(w) * h * 4, 0) {}
  std::uint8_t* pixel(int x, int y) { return &rgba[(static_cast<std::size_t>(y) * width + x) * 4]; }
  const std::uint8_t* pixel(int x, int y) const {
    return &rgba[(static_cast<std::size_t>(y) * width + x) * 4];
  }
};

/// Writes an 8-bit RGB PNG (alpha dropped unless `with_alpha`) atomically. The bytes depend
/// only on the pixels (fixed compression settings, no time stamp).
/// @throws std::runtime_error / std::system_error naming `path` on failure.
void write_png(const std::string& path, const Image& image, bool with_alpha = false);

/// Reads an 8-bit RGB or RGBA PNG (RGB gets alpha 255).
/// @throws std::runtime_error naming `path` when it is missing or not such a PNG.
Image read_png(const std::string& path);

/// A box-filtered copy at most `max_width` wide, keeping the aspect ratio.
Image downscale(const Image& image, int max_width);

/// A grid of `tiles` (all the same size) with `labels[i]` (digits, '-' and letters
/// F, R, A, M, E) drawn in the bottom-left corner of each; `columns` tiles per row.
Image contact_sheet(const std::vector<Image>& tiles, const std::vector<std::string>& labels,
                    int columns);

}  // namespace shellmpm
