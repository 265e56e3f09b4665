#include "render/animation.hpp"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "render/image_io.hpp"
#include "scene/cleanup.hpp"

namespace saltus::render {

namespace {

// A round length near x: 1, 2 or 5 times a power of ten.
double roundLength(double x) {
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  const double m = x / p;
  return (m < 1.5 ? 1 : m < 3.5 ? 2 : 5) * p;
}

}  // namespace

CameraMode parseCameraMode(const std::string& name) {
  if (name == "auto") return CameraMode::Auto;
  if (name == "follow") return CameraMode::Follow;
  if (name == "side") return CameraMode::Side;
  if (name == "top") return CameraMode::Top;
  throw std::invalid_argument("unknown camera '" + name + "' (expected auto, follow, side or top)");
}

Animation::Animation(const scene::Scene& scene, const TrajectorySource& source, const AnimationOptions& options,
                     std::ostream& warnings)
    : scene_(scene), source_(source), options_(options), geometry_(scene, warnings) {
  if (!(options.fps > 0) || !std::isfinite(options.fps) || options.fps > 1000)
    throw std::invalid_argument("fps must be a number in (0, 1000], got " + std::to_string(options.fps));
  if (!(options.speed > 0) || !std::isfinite(options.speed))
    throw std::invalid_argument("speed must be a positive number, got " + std::to_string(options.speed));
  if (options.width < 2 || options.height < 2 || options.width > 8192 || options.height > 8192)
    throw std::invalid_argument("image size must be 2 … 8192 pixels each way, got " + std::to_string(options.width) +
                                "x" + std::to_string(options.height));

  // Frame times: t0 + k · speed / fps up to the end of the trajectory.
  const double t0 = source.startTime(), t1 = source.endTime();
  const double step = options.speed / options.fps;
  const double frames = std::floor((t1 - t0) / step + 1e-9) + 1;
  if (!(frames <= kMaxFrames)) {
    char what[256];
    std::snprintf(what, sizeof what,
                  "speed: %g s of trajectory (t = %g ... %g s) at speed %g and %g fps is %.3g frames, more than a "
                  "million: lower the fps or raise the speed",
                  t1 - t0, t0, t1, options.speed, options.fps, frames);
    throw std::invalid_argument(what);
  }
  const long n = static_cast<long>(frames);
  for (long k = 0; k < n; ++k) times_.push_back(t0 + k * step);

  // Poses and bounds; contact points also count projected onto their surfaces, so the surface
  // under the model is in view.
  for (double t : times_) {
    poses_.push_back(geometry_.pose(source.q(t)));
    Bounds b = geometry_.bounds(poses_.back());
    centers_.push_back(b.center());
    bounds_.add(b);
  }
  for (const SceneGeometry::Pose& pose : poses_)
    for (std::size_t c = 0; c < pose.p_contact.size(); ++c) bounds_.add(pose.onPlane(c));
  if (bounds_.empty()) bounds_.addSphere(Eigen::Vector3d::Zero(), 0.5);
  radius_ = std::max(0.5 * bounds_.size().norm(), geometry_.characteristicLength());

  // Camera direction (from the target towards the camera) and distance.
  switch (options.camera) {
    case CameraMode::Auto:
    case CameraMode::Follow: direction_ = Eigen::Vector3d(0.35, -1, 0.4).normalized(); break;
    case CameraMode::Side: direction_ = Eigen::Vector3d(0, -1, 0.05).normalized(); break;
    case CameraMode::Top: direction_ = Eigen::Vector3d(0, -0.05, 1).normalized(); break;
  }
  const double fov = 0.6, aspect = double(options.width) / options.height, margin = 0.85;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  // Framing keeps a small box around very thin bounds (a point mass moving on a line).
  Bounds framed = bounds_;
  framed.addSphere(bounds_.center(), 0.25 * radius_);
  if (options.camera == CameraMode::Follow) {
    distance_ = 0;
    for (const SceneGeometry::Pose& pose : poses_) {
      Bounds b = geometry_.bounds(pose);
      b.addSphere(b.center(), 0.5 * radius_);  // half the whole motion's size around the model
      distance_ = std::max(distance_, fitDistance(b, b.center(), direction_, up, fov, aspect, margin));
    }
  } else {
    distance_ = fitDistance(framed, framed.center(), direction_, up, fov, aspect, margin);
  }

  // Renderer settings scaled to the scene.
  settings_.width = options.width;
  settings_.height = options.height;
  settings_.supersample = options.supersample;
  settings_.surface_center = bounds_.center();
  settings_.surface_extent = 3 * (radius_ + distance_);
  settings_.tile = roundLength(radius_ / 2.5);
  settings_.fog_start = distance_ + radius_;
  settings_.fog_end = distance_ + 5 * radius_;
  settings_.belt_width = std::max(radius_, 2 * geometry_.characteristicLength());
  settings_.arrow_radius = 0.012 * radius_;

  // Force arrows: the 90th percentile of the non-zero force magnitudes over the frames is drawn
  // 0.3 radius long (a few impact-like peaks do not shrink the rest), and no arrow is longer
  // than twice that.
  std::vector<double> magnitudes;
  for (double t : times_)
    for (const ContactLoad& f : source.contactForces(t))
      if (f.magnitude() > 0) magnitudes.push_back(f.magnitude());
  if (!magnitudes.empty()) {
    std::sort(magnitudes.begin(), magnitudes.end());
    const double reference = magnitudes[static_cast<std::size_t>(0.9 * (magnitudes.size() - 1))];
    if (reference > 0) force_scale_ = 0.3 * radius_ / reference;
  }
}

Camera Animation::camera(int frame) const {
  const double fov = 0.6;
  const Eigen::Vector3d center = options_.camera == CameraMode::Follow ? centers_[frame] : bounds_.center();
  Camera camera = lookFrom(center, direction_, distance_, fov, radius_);
  camera.far = 2 * (settings_.surface_extent + distance_);
  return camera;
}

FrameContent Animation::content(int frame) const {
  const double t = times_[frame];
  FrameContent out;
  out.pose = poses_[frame];
  for (const scene::Surface& s : scene_.surfaces) out.surface_shift.push_back(surfaceTravel(s, beltDirection(s), t));
  const std::vector<ContactLoad> forces = source_.contactForces(t);
  for (std::size_t c = 0; c < out.pose.p_contact.size() && c < forces.size(); ++c) {
    const contact::PlaneFrame<double>& frame = out.pose.contact_frame[c];
    Eigen::Vector3d f = forces[c].world(frame.normal, frame.tangents) * force_scale_;
    const double longest = 0.6 * radius_;
    if (f.norm() > longest) f *= longest / f.norm();
    if (f.norm() > 0) out.arrows.push_back({out.pose.p_contact[c], f});
  }
  const double lifetime = options_.marker_seconds * options_.speed;  // trajectory time
  for (const Impulse& impulse : source_.impulses()) {
    if (impulse.t > t || t >= impulse.t + lifetime) continue;
    // where the contact point was at the impulse (positions are continuous there)
    const SceneGeometry::Pose at = geometry_.pose(source_.q(impulse.t));
    const std::size_t c = static_cast<std::size_t>(impulse.contact);
    out.markers.push_back({at.onPlane(c), at.contact_frame[c].normal, 0.12 * radius_, (t - impulse.t) / lifetime});
  }
  return out;
}

namespace {

namespace fs = std::filesystem;

// The frames folder is written as a temporary folder beside it and renamed into place when every
// frame and the video are done, so that an interrupted or failed render leaves no frames. An
// existing folder is replaced only when it holds nothing but frame_NNNNN.png files (an earlier
// render's), never a folder of the user's.
class FramesFolder {
 public:
  explicit FramesFolder(const std::string& dir) {
    fs::path p(dir);
    if (!p.has_filename()) p = p.parent_path();  // "frames/"
    target_ = p;
    std::error_code error;
    const auto status = fs::symlink_status(target_, error);
    if (fs::exists(status)) {
      if (!fs::is_directory(status))
        throw std::runtime_error(dir + ": exists and is not a folder; refusing to replace it with the frames");
      for (const auto& entry : fs::directory_iterator(target_)) {
        const std::string name = entry.path().filename().string();
        if (!(name.size() == 15 && name.rfind("frame_", 0) == 0 && name.substr(11) == ".png"))
          throw std::runtime_error(dir + ": holds files other than frame_NNNNN.png (" + name +
                                   "); refusing to replace it with the frames");
      }
    }
    scene::removeStaleTemporaries(target_.parent_path().string());
    temporary_ = std::make_unique<scene::ScopedTemporary>(scene::temporaryName(target_.string()));
    fs::create_directories(temporary_->path(), error);
    if (error) throw std::runtime_error(dir + ": cannot create the frames folder (" + error.message() + ")");
  }
  std::string file(int k) const {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", k);
    return (fs::path(temporary_->path()) / name).string();
  }
  void commit() {
    scene::ScopedTemporary old(scene::temporaryName(target_.string(), ".old"));
    std::error_code error;
    if (fs::exists(target_)) fs::rename(target_, old.path(), error);
    if (!error) fs::rename(temporary_->path(), target_, error);
    if (error) throw std::runtime_error(target_.string() + ": cannot move the frames into place (" + error.message() + ")");
    temporary_->keep();
  }

 private:
  fs::path target_;
  std::unique_ptr<scene::ScopedTemporary> temporary_;
};

}  // namespace

int renderAnimation(const Animation& animation, const std::string& video_path, const std::string& frames_dir,
                    const std::function<void(int, int)>& progress) {
  Renderer renderer(animation.geometry(), animation.settings());
  std::unique_ptr<VideoWriter> video;
  if (!video_path.empty())
    video = std::make_unique<VideoWriter>(video_path, renderer.width(), renderer.height(), animation.fps());
  std::unique_ptr<FramesFolder> frames;
  if (!frames_dir.empty()) frames = std::make_unique<FramesFolder>(frames_dir);
  const int n = animation.frames();
  for (int k = 0; k < n; ++k) {
    renderer.draw(animation.camera(k), animation.content(k));
    if (frames) writePng(frames->file(k), renderer.rgb(), renderer.width(), renderer.height());
    if (video) video->addFrame(renderer.rgb());
    if (progress) progress(k + 1, n);
  }
  if (video) video->finish();
  if (frames) frames->commit();
  return n;
}

}  // namespace saltus::render
