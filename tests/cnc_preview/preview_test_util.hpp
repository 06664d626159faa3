// Shared by the preview tests: a scratch folder per test (parallel-safe), a PNG read back
// through cairo, and pixel colour classes that survive antialiasing (a colour blended with the
// white background keeps its dominant channel).
#pragma once

#include <cairo.h>
#include <stdlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "cnc_run_harness.hpp"
#include "preview.hpp"

namespace preview_test {

namespace fs = std::filesystem;

using cnc_test::ScratchDir;
using cnc_test::slurp;

struct SurfaceDeleter {
    void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};

// A PNG read back; status() is not CAIRO_STATUS_SUCCESS when the file is not a valid PNG.
class Png {
  public:
    explicit Png(const fs::path& p) : surface_(cairo_image_surface_create_from_png(p.c_str())) {
        cairo_surface_flush(surface_.get());
    }
    cairo_status_t status() const { return cairo_surface_status(surface_.get()); }
    int width() const { return cairo_image_surface_get_width(surface_.get()); }
    int height() const { return cairo_image_surface_get_height(surface_.get()); }
    // 0xRRGGBB of the pixel at (x, y).
    std::uint32_t rgb(int x, int y) const {
        const unsigned char* row =
            cairo_image_surface_get_data(surface_.get()) +
            static_cast<std::ptrdiff_t>(y) * cairo_image_surface_get_stride(surface_.get());
        std::uint32_t px;
        std::memcpy(&px, row + 4 * x, sizeof px);
        return px & 0xffffffu;
    }

  private:
    std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface_;
};

enum class Hue { Blue, Red, Green, Other };

// Feed blue, rapid red and start green are saturated; text, frames and the end marker are grey.
inline Hue hue(std::uint32_t rgb) {
    const int r = static_cast<int>(rgb >> 16 & 0xff), g = static_cast<int>(rgb >> 8 & 0xff),
              b = static_cast<int>(rgb & 0xff);
    constexpr int kMargin = 40;
    if (b - std::max(r, g) > kMargin) return Hue::Blue;
    if (r - std::max(g, b) > kMargin) return Hue::Red;
    if (g - std::max(r, b) > kMargin) return Hue::Green;
    return Hue::Other;
}

struct PixelBounds {
    int count = 0;
    int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
    int width() const { return count ? x1 - x0 + 1 : 0; }
    int height() const { return count ? y1 - y0 + 1 : 0; }
};

// How many pixels of a hue lie inside a box, and their bounding box.
inline PixelBounds find_hue(const Png& png, const cncrun::PixelBox& box, Hue want) {
    PixelBounds b;
    for (int y = static_cast<int>(box.y); y < static_cast<int>(box.y + box.h); ++y)
        for (int x = static_cast<int>(box.x); x < static_cast<int>(box.x + box.w); ++x) {
            if (hue(png.rgb(x, y)) != want) continue;
            ++b.count;
            b.x0 = std::min(b.x0, x);
            b.y0 = std::min(b.y0, y);
            b.x1 = std::max(b.x1, x);
            b.y1 = std::max(b.y1, y);
        }
    return b;
}

}  // namespace preview_test
