// saltus::openSolution, openTrajectoryCsv and renderTrajectory (saltus/saltus.hpp): a trajectory with its
// scene, drawn off-screen into PNG frames and/or an MP4, or frame by frame in memory.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "render/csv_trajectory.hpp"
#include "saltus/collocation_source.hpp"
#include "saltus/saltus.hpp"

namespace saltus {

namespace {

namespace fs = std::filesystem;

// The scene of an optimisation output directory, from its summary.json ("source", "parameters").
scene::Scene sceneOfSolutionDirectory(const fs::path& dir) {
  const fs::path summary_path = dir / "summary.json";
  std::ifstream in(summary_path);
  if (!in)
    throw std::runtime_error(summary_path.string() +
                             ": missing; a directory to render must be the output of 'saltus optimize' "
                             "(summary.json and trajectory.csv); for a CSV file give --scene");
  nlohmann::json summary;
  try {
    summary = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(summary_path.string() + ": not valid JSON (" + e.what() + ")");
  }
  if (!summary.is_object() || !summary.contains("source") || !summary["source"].is_string())
    throw std::runtime_error(summary_path.string() +
                             ": no key \"source\" (a string: the problem file or builtin:<name>) to load the scene from");
  if (!summary.contains("parameters") || !summary["parameters"].is_object())
    throw std::runtime_error(summary_path.string() + ": no key \"parameters\" (an object: parameter name -> value)");
  Parameters parameters;
  for (const auto& [name, value] : summary["parameters"].items()) {
    if (!value.is_number())
      throw std::runtime_error(summary_path.string() + ": parameters." + name + ": expected a number, got " + value.dump());
    parameters[name] = value.get<double>();
  }
  std::string source = summary["source"].get<std::string>();
  if (source.rfind("builtin:", 0) == 0) source = source.substr(8);
  return collocation::loadProblem(source, parameters).scene;
}

}  // namespace

RenderInput openSolution(const std::string& dir, bool allow_changed_problem) {
  const fs::path path(dir);
  std::error_code error;
  if (!fs::is_directory(path, error)) throw std::runtime_error(dir + ": not a 'saltus optimize' output directory");
  RenderInput input;
  if (fs::exists(path / "variables.csv")) {
    // The collocation polynomials between the points; the scene of the rebuilt problem.
    auto collocation = std::make_shared<const CollocationSource>(CollocationSource::load(dir));
    input.scene = collocation->scene();
    collocation::checkSameProblem(collocation->solution(), allow_changed_problem);
    input.problem_changed = collocation->problemChanged();
    input.trajectory = std::move(collocation);
  } else {  // an older output directory: straight lines between the CSV rows
    input.scene = sceneOfSolutionDirectory(path);
    input.trajectory = std::make_shared<const render::CsvTrajectory>((path / "trajectory.csv").string(), input.scene);
  }
  return input;
}

RenderInput openTrajectoryCsv(const std::string& csv_path, scene::Scene scene) {
  RenderInput input;
  input.scene = std::move(scene);
  input.trajectory = std::make_shared<const render::CsvTrajectory>(csv_path, input.scene);
  return input;
}

RenderReport renderTrajectory(const RenderInput& input, const render::AnimationOptions& options, const std::string& video_path,
                    const std::string& frames_dir, std::ostream& warnings,
                    const std::function<void(int, int)>& progress) {
  const render::Animation animation(input.scene, *input.trajectory, options, warnings);
  RenderReport report;
  report.start_time = input.trajectory->startTime();
  report.end_time = input.trajectory->endTime();
  const auto start = std::chrono::steady_clock::now();
  report.frames = render::renderAnimation(animation, video_path, frames_dir, progress);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

FrameRenderer::FrameRenderer(RenderInput input, const render::AnimationOptions& options, std::ostream& warnings)
    : input_(std::move(input)),
      animation_(std::make_unique<render::Animation>(input_.scene, *input_.trajectory, options, warnings)),
      renderer_(std::make_unique<render::Renderer>(animation_->geometry(), animation_->settings())) {}

FrameRenderer::~FrameRenderer() = default;

int FrameRenderer::frames() const { return animation_->frames(); }
double FrameRenderer::time(int frame) const { return animation_->time(frame); }
int FrameRenderer::width() const { return renderer_->width(); }
int FrameRenderer::height() const { return renderer_->height(); }

const std::vector<std::uint8_t>& FrameRenderer::draw(int frame) {
  if (frame < 0 || frame >= frames())
    throw std::out_of_range("frame " + std::to_string(frame) + ": expected 0 … " + std::to_string(frames() - 1));
  renderer_->draw(animation_->camera(frame), animation_->content(frame));
  return renderer_->rgb();
}

}  // namespace saltus
