// The pixels of a drawn frame that are not background: how many, and their centroid (pixel
// centres, x right, y down), for checking where the renderer put a body.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include <Eigen/Core>

namespace saltus::testing {

struct Centroid {
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  int pixels = 0;
};

// rgb: width × height × 3 bytes, top row first; a pixel is background when every channel is
// within 8 of the background colour's.
inline Centroid nonBackground(const std::vector<std::uint8_t>& rgb, int width, int height, const Eigen::Vector3f& background) {
  Centroid c;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::uint8_t* p = &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
      bool differs = false;
      for (int k = 0; k < 3; ++k) differs = differs || std::abs(int(p[k]) - int(std::lround(255 * background[k]))) > 8;
      if (!differs) continue;
      c.at += Eigen::Vector2d(x + 0.5, y + 0.5);
      ++c.pixels;
    }
  if (c.pixels) c.at /= c.pixels;
  return c;
}

}  // namespace saltus::testing
