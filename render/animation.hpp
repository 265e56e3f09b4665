// A trajectory as a sequence of frames: frame times at a chosen fps and playback speed, the
// camera (framing the whole trajectory, or following the model), the surfaces' travel, force
// arrows and impulse markers of each frame; and rendering them all to PNG files and/or an MP4.
#pragma once

#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "render/camera.hpp"
#include "render/geometry.hpp"
#include "render/renderer.hpp"
#include "render/trajectory_source.hpp"

namespace saltus::render {

//  auto:   fixed camera, oblique view from −y and above, framing the whole trajectory
//  follow: the same view direction, the target follows the model's bounding box centre at a
//          fixed distance that fits the largest pose
//  side:   fixed, looking along +y (the x–z plane of planar scenes), framing the trajectory
//  top:    fixed, looking down −z, framing the trajectory
enum class CameraMode { Auto, Follow, Side, Top };
// "auto", "follow", "side", "top"; throws std::invalid_argument listing them.
CameraMode parseCameraMode(const std::string& name);

// The most frames an animation draws (an hour at 280 fps): more is a mistake of speed or fps.
constexpr double kMaxFrames = 1e6;

struct AnimationOptions {
  double fps = 60;     // frames per second of video
  double speed = 1;    // trajectory seconds per video second (0.25: four times slower)
  int width = 1280, height = 720;
  int supersample = 1;
  CameraMode camera = CameraMode::Auto;
  double marker_seconds = 0.3;  // how long an impulse marker shows, video seconds
};

class Animation {
 public:
  // Throws std::invalid_argument on bad options (fps, speed, size) naming them.
  Animation(const scene::Scene& scene, const TrajectorySource& source, const AnimationOptions& options,
            std::ostream& warnings);

  int frames() const { return static_cast<int>(times_.size()); }
  double time(int frame) const { return times_[frame]; }
  double fps() const { return options_.fps; }
  const SceneGeometry& geometry() const { return geometry_; }
  // Settings for a Renderer (size, surfaces' extent and tiles, arrow size).
  const RenderSettings& settings() const { return settings_; }
  Camera camera(int frame) const;
  FrameContent content(int frame) const;
  const Bounds& bounds() const { return bounds_; }  // of the whole trajectory

 private:
  const scene::Scene& scene_;
  const TrajectorySource& source_;
  AnimationOptions options_;
  SceneGeometry geometry_;
  std::vector<double> times_;
  std::vector<SceneGeometry::Pose> poses_;
  std::vector<Eigen::Vector3d> centers_;  // per frame: centre of the pose's bounds (follow camera)
  Bounds bounds_;
  Eigen::Vector3d direction_;  // from target towards the camera
  double distance_ = 1, radius_ = 1;
  double force_scale_ = 0;     // arrow length per newton
  RenderSettings settings_;
};

// Renders every frame of the animation: PNG files frames_dir/frame_00000.png … when frames_dir
// is not empty, and an H.264 MP4 at video_path (through ffmpeg) when it is not empty.
// `progress(done, total)` is called after each frame. Returns the number of frames.
int renderAnimation(const Animation& animation, const std::string& video_path, const std::string& frames_dir,
                    const std::function<void(int, int)>& progress = {});

}  // namespace saltus::render
