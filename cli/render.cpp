// saltus render TRAJECTORY.csv --scene SCENE | DIR: draws a trajectory off-screen (render/,
// OSMesa) into PNG frames and/or an H.264 MP4 (through ffmpeg). DIR is an output directory of
// `saltus optimize` (saltus::openSolution: drawn through the collocation polynomials). A bare
// CSV needs --scene (and the --set values it was simulated with). Files appear only when
// complete.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "saltus/saltus.hpp"

namespace saltus::cli {

namespace {

namespace fs = std::filesystem;

struct RenderCliOptions {
  std::string input;
  std::optional<std::string> scene;
  std::vector<std::string> set;
  std::string out;
  bool allow_changed_problem = false;
  std::string frames;
  double fps = 60;
  double speed = 1;
  int width = 1280, height = 720;
  int antialias = 1;
  std::string camera = "auto";
};

int renderCommand(const RenderCliOptions& opt) {
  if (!opt.out.empty()) checkOutputTarget("--out", opt.out, OutputTarget::RegularFile);
  if (!opt.frames.empty()) checkOutputTarget("--frames", opt.frames, OutputTarget::Folder);
  if (opt.out.empty() && opt.frames.empty())
    throw UsageError("nothing to write: give --out VIDEO.mp4 and/or --frames DIR");
  if (!(opt.fps > 0) || !std::isfinite(opt.fps) || opt.fps > 1000)
    throw UsageError("--fps: expected frames per second in (0, 1000], got " + formatNumber(opt.fps));
  if (!(opt.speed > 0) || !std::isfinite(opt.speed))
    throw UsageError("--speed: expected a positive playback speed (0.25: four times slower), got " + formatNumber(opt.speed));
  if (opt.width < 2 || opt.width > 8192 || opt.height < 2 || opt.height > 8192)
    throw UsageError("--width/--height: expected 2 … 8192 pixels, got " + std::to_string(opt.width) + "x" +
                     std::to_string(opt.height));
  if (!opt.out.empty() && (opt.width % 2 != 0 || opt.height % 2 != 0))
    throw UsageError("--width/--height: an H.264 video needs even sizes, got " + std::to_string(opt.width) + "x" +
                     std::to_string(opt.height));
  if (opt.antialias < 1 || opt.antialias > 4) throw UsageError("--antialias: expected 1 … 4, got " + std::to_string(opt.antialias));
  render::AnimationOptions options;
  try {
    options.camera = render::parseCameraMode(opt.camera);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--camera: ") + e.what());
  }
  options.fps = opt.fps;
  options.speed = opt.speed;
  options.width = opt.width;
  options.height = opt.height;
  options.supersample = opt.antialias;

  // The scene and the trajectory.
  const fs::path input(opt.input);
  std::error_code error;
  if (!fs::exists(input, error)) throw std::runtime_error(opt.input + ": no such file or directory");
  RenderInput trajectory;
  if (fs::is_directory(input, error)) {
    if (opt.scene || !opt.set.empty())
      throw UsageError("--scene/--set: not used with a 'saltus optimize' directory (its summary.json names the scene)");
    trajectory = openSolution(opt.input, opt.allow_changed_problem);
    if (!trajectory.problem_changed.empty())
      std::cerr << "saltus render: warning: " << trajectory.problem_changed << ": drawn in the problem as it is now\n";
  } else {
    if (!opt.scene) throw UsageError("--scene: required with a trajectory CSV (the scene it was simulated in)");
    trajectory = openTrajectoryCsv(opt.input, scene::loadScene(*opt.scene, parseSetOptions(opt.set)));
  }

  // Progress: a bar redrawn in place on a terminal, else a line every 25 % for long renders.
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  int last_quarter = 0;
  auto progress = [&](int done, int total) {
    if (tty) {
      if (done % 4 != 0 && done != total) return;
      const int width = 30, filled = width * done / total;
      std::cerr << "\rsaltus render: [" << std::string(filled, '#') << std::string(width - filled, ' ') << "] "
                << 100 * done / total << "% " << done << "/" << total << (done == total ? "\n" : "") << std::flush;
    } else if (total >= 200 && 4 * done / total > last_quarter) {
      last_quarter = 4 * done / total;
      std::cerr << "saltus render: " << 25 * last_quarter << "% (" << done << "/" << total << " frames)\n";
    }
  };
  RenderReport report;
  try {
    report = renderTrajectory(trajectory, options, opt.out, opt.frames, std::cerr, progress);
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).rfind("speed: ", 0) == 0) throw optionError(e);  // the frame count
    throw;
  }
  const int frames = report.frames;
  const double seconds = report.seconds;

  std::cerr << "saltus render: " << frames << " frames " << opt.width << "x" << opt.height << " (t = "
            << formatNumber(report.start_time) << " … " << formatNumber(report.end_time) << " s at "
            << formatNumber(opt.fps) << " fps, speed " << formatNumber(opt.speed) << ") in " << formatNumber(seconds, 3)
            << " s (" << formatNumber(frames / std::max(seconds, 1e-9), 3) << " frames/s)";
  if (!opt.out.empty()) std::cerr << " -> " << opt.out;
  if (!opt.frames.empty()) std::cerr << (opt.out.empty() ? " -> " : ", ") << opt.frames << "/";
  std::cerr << "\n";
  return 0;
}

}  // namespace

Command addRenderCommand(CLI::App& saltus) {
  auto opt = std::make_shared<RenderCliOptions>();
  CLI::App* app = saltus.add_subcommand("render", "Draw a trajectory into an MP4 video and/or PNG frames (off-screen)");
  app->add_option("TRAJECTORY", opt->input,
                  "trajectory CSV (saltus simulate; needs --scene) or a 'saltus optimize' output directory")
      ->required();
  app->add_option("--scene", opt->scene, "scene of a trajectory CSV: built-in name or scenario file");
  app->add_option("--set", opt->set, "override a scene parameter: name=value (repeatable), as when simulated");
  app->add_option("--out", opt->out, "H.264 MP4 video to write (through the ffmpeg program)");
  app->add_option("--frames", opt->frames, "directory to write PNG frames into (frame_00000.png, ...)");
  app->add_flag("--allow-changed-problem", opt->allow_changed_problem,
                "draw a solution even when its problem file changed since the solve (in the problem as it is now)");
  app->add_option("--fps", opt->fps, "video frames per second")->capture_default_str();
  app->add_option("--speed", opt->speed, "playback speed: trajectory seconds per video second (0.25: slow motion)")
      ->capture_default_str();
  app->add_option("--width", opt->width, "image width [pixels]")->capture_default_str();
  app->add_option("--height", opt->height, "image height [pixels]")->capture_default_str();
  app->add_option("--camera", opt->camera, "auto (fixed, frames the whole trajectory), follow, side or top")
      ->capture_default_str();
  app->add_option("--antialias", opt->antialias, "supersampling factor 1 … 4 (2: four samples a pixel, 4x slower)")
      ->capture_default_str();
  return {app, [opt] { return renderCommand(*opt); }};
}

}  // namespace saltus::cli
