// Draws one frame of a scene with OSMesa (off-screen OpenGL, fixed-function pipeline, no
// display): the posed shapes (geometry.hpp) lit by a directional key light and a fill light from
// the camera, the scene's surfaces (a checkered plane; a belt, a surface whose velocity schedule
// moves, as a slab with stripes across its motion that move with it), planar projected shadows
// of the shapes on each surface, contact-force arrows and impulse markers drawn over everything.
// The image is RGB, 8 bits per channel, top row first.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "render/camera.hpp"
#include "render/geometry.hpp"

namespace saltus::render {

// What changes from frame to frame besides the camera.
struct FrameContent {
  SceneGeometry::Pose pose;
  std::vector<double> surface_shift;  // per surface: distance its material has moved along its stripe direction [m]
  struct Arrow {
    Eigen::Vector3d tail, vector;  // world [m]: tail at the contact point
  };
  std::vector<Arrow> arrows;
  struct Marker {
    Eigen::Vector3d center, normal;  // world; normal: the surface's
    double size = 0.05;              // outer radius [m]
    double age = 0;                  // 0 at the impulse instant .. 1 when it disappears
  };
  std::vector<Marker> markers;
};

struct RenderSettings {
  int width = 1280, height = 720;
  int supersample = 1;   // renders at supersample × the size and averages (antialiasing)
  bool surfaces = true;  // draw the scene's surfaces (and the shadows on them)
  bool shadows = true;
  Eigen::Vector3f background{0.89f, 0.92f, 0.96f};
  // Surfaces are drawn as squares of half-size surface_extent around surface_center (projected
  // onto each plane); checker / stripe period tile [m].
  Eigen::Vector3d surface_center = Eigen::Vector3d::Zero();
  double surface_extent = 5;
  double tile = 0.25;
  double belt_width = 0.5;  // across its motion [m]
  double arrow_radius = 0.01;
  // Linear fog towards the background between these eye distances [m] (fog_end = 0: none), so
  // the far field of a surface fades instead of aliasing.
  double fog_start = 0, fog_end = 0;
  Eigen::Vector3d light_direction{0.45, -0.35, 1.0};  // towards the key light (world)
};

class Renderer {
 public:
  // Creates the OSMesa context; throws std::runtime_error when it cannot.
  Renderer(const SceneGeometry& geometry, const RenderSettings& settings);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws the frame; rgb() then holds it.
  void draw(const Camera& camera, const FrameContent& frame);
  const std::vector<std::uint8_t>& rgb() const { return rgb_; }
  int width() const { return settings_.width; }
  int height() const { return settings_.height; }

 private:
  // The parts of draw(), in order (renderer.cpp).
  Eigen::Vector3d setUpFrame(const Camera& camera);
  void drawSurfaces(const FrameContent& frame);
  void drawShadows(const FrameContent& frame, const Eigen::Vector3d& light);
  void drawModel(const FrameContent& frame);
  void drawArrows(const FrameContent& frame);
  void drawMarkers(const FrameContent& frame);
  void downsample();

  struct Gl;
  const SceneGeometry& geometry_;
  RenderSettings settings_;
  std::unique_ptr<Gl> gl_;
  std::vector<std::uint8_t> rgb_;
};

}  // namespace saltus::render
