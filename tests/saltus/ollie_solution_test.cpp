// The full-body Ollie's saved solutions (ollie_impulsive, the paper's problem; ollie_assist_0.5,
// with an assist on the rider's base), beyond the checks every saved solution passes
// (saved_solutions_test.cpp): the horizontal momentum of board and rider changed by the assist
// alone (the ground is frictionless; without an assist, constant); replayed element by element in
// both engines with the trick's contact events (tail strike, landing) recurring; drawn, the board
// in the air at the air goal.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collocation/solution.hpp"
#include "tests/saltus/saved_solution_fixture.hpp"
#include "tests/support/pixels.hpp"

namespace {

using namespace saltus;
using namespace saltus::saved_solutions;
using collocation::Quantity;

class OllieSolution : public SavedSolutionTest {};

// The ground pushes board and rider only along its normal (the wheels and the tail are
// frictionless; the feet's forces on the deck are internal), so their horizontal momentum, m ẋ_c,
// changes by the assist's horizontal force on the rider's base alone (none in the paper's
// problem, where the centre of mass cannot move along the ground): across every velocity jump not
// at all, and from the start to every element's end by ∫ u_x dt (each element's Gauss rule on the
// inputs at its collocation points), up to the collocation's error between those points.
TEST_P(OllieSolution, TheHorizontalMomentumChangesByTheAssistAlone) {
  const collocation::Transcription& t = transcription();
  const auto& model = t.models().model<double>();
  auto& data = t.models().data<double>();
  const std::vector<collocation::Sample> samples = collocation::trajectory(t, solution_->x);
  const int rider_x = model.coordinateIndex("rider_x");
  const auto input = std::find(problem().inputs.begin(), problem().inputs.end(), rider_x);
  ASSERT_NE(input, problem().inputs.end()) << "the assist's input on rider_x";
  const auto u_x = static_cast<Eigen::Index>(input - problem().inputs.begin());
  const double mass = model.totalMass(), P = problem().P;
  auto momentum = [&](const collocation::Sample& s) { return mass * comVelocity(model, data, s.q, s.v).x(); };
  const double start = momentum(samples.front());
  double assist_impulse = 0, largest_assist_impulse = 0, worst_jump = 0, worst_element = 0;
  std::vector<double> u;  // the element's inputs at its collocation points
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const collocation::Sample& s = samples[k];
    if (s.point >= 1 && s.point <= P) u.push_back(s.u[u_x]);
    if (s.point != P + 1) continue;  // an element's end
    const double h = s.t - samples[k - static_cast<std::size_t>(P) - 1].t;
    for (int j = 0; j < P; ++j) assist_impulse += h * t.lg().b[j] * u[static_cast<std::size_t>(j)];
    largest_assist_impulse = std::max(largest_assist_impulse, std::abs(assist_impulse));
    u.clear();
    worst_element = std::max(worst_element, std::abs(momentum(s) - start - assist_impulse));
    if (k + 1 < samples.size()) worst_jump = std::max(worst_jump, std::abs(momentum(samples[k + 1]) - momentum(s)));
  }
  const double weight_impulse = mass * -model.gravity.z() * samples.back().t;  // m g T
  std::cout << GetParam() << ": horizontal momentum " << start << " N s at the start; the assist's impulse "
            << assist_impulse << " N s at the end, up to " << largest_assist_impulse << " on the way; largest change across a jump " << worst_jump
            << ", largest difference from the assist's impulse at an element's end " << worst_element
            << " N s (m g T = " << weight_impulse << " N s)\n";
  EXPECT_NEAR(start, 0, 1e-6 * weight_impulse);  // from rest
  EXPECT_LT(worst_jump, 1e-4 * weight_impulse);
  EXPECT_LT(worst_element, 0.01 * weight_impulse);
}

// An element-by-element replay of a saved Ollie (from the optimised state at every mesh point,
// so that the rider's unstable balance does not carry one element's error into the next) in
// Saltus' time-stepper and in Bullet, with the optimised trajectory's samples.
struct OllieReplay {
  verify::ReplayResult result;
  double goal = 0;  // [20, 0], the air goal's mesh time
  std::vector<collocation::Sample> samples;
  static const std::vector<std::string>& ground() {
    static const std::vector<std::string> names = {"rear_wheel", "front_wheel", "tail"};
    return names;
  }
  bool onGround(const verify::EventMatch& m) const {
    const std::string& contact = result.contacts[static_cast<std::size_t>(m.optimised.contact)];
    return std::find(ground().begin(), ground().end(), contact) != ground().end();
  }
};

// Replayed once per solution for the tests below (a replay of the Ollie takes seconds).
const OllieReplay& replayOllie(const std::string& name, const collocation::Transcription& t, const Eigen::VectorXd& x) {
  static std::map<std::string, OllieReplay> replays;
  if (const auto found = replays.find(name); found != replays.end()) return found->second;
  verify::ReplayOptions o;
  o.engines = {verify::EngineKind::Saltus, verify::EngineKind::Bullet};
  o.restart = verify::Restart::Mesh;
  o.max_series = 200;
  OllieReplay r{saltus::replay(solutionDir(name), o), 0, collocation::trajectory(t, x)};
  if (r.result.mesh_times.size() > 20) r.goal = r.result.mesh_times[19];
  return replays.emplace(name, std::move(r)).first->second;
}

// Replayed element by element, the trick recurs in Saltus' time-stepper and in Bullet within the
// match window (10 ms): the tail strike before the air goal and the first landing on a wheel
// after it, and both wheels touch down after the goal. Every optimised impact is at a closed
// contact: a velocity jump at a joint stop is no scene contact's event, even where a wheel in the
// air carries a trace of an impulse (the solver's complementarity tolerance).
TEST_P(OllieSolution, ReplayedElementByElementTheTrickRecursInSaltusAndBullet) {
  const OllieReplay& replay = replayOllie(GetParam(), transcription(), solution_->x);
  const verify::ReplayResult& r = replay.result;
  ASSERT_EQ(r.engines.size(), 2u);
  ASSERT_GT(r.mesh_times.size(), 20u);
  for (const verify::ContactEvent& ev : r.optimised_events) {
    if (ev.kind != verify::ContactEvent::Impact && ev.kind != verify::ContactEvent::ImpactWithoutCollision) continue;
    const auto before = std::find_if(replay.samples.begin(), replay.samples.end(), [&](const collocation::Sample& s) {
      return std::abs(s.t - ev.t) < 1e-9;
    });
    ASSERT_NE(before, replay.samples.end()) << "an impact at a mesh point, t = " << ev.t;
    EXPECT_LT(before->contacts[static_cast<std::size_t>(ev.contact)].gap, 1e-3)
        << verify::eventKindName(ev.kind) << " of " << r.contacts[static_cast<std::size_t>(ev.contact)] << " at " << ev.t;
  }
  for (const verify::EngineReplay& e : r.engines) {
    const std::string engine = verify::engineName(e.engine);
    EXPECT_TRUE(e.completed) << engine << ": " << e.message;
    const verify::EventMatch* strike = nullptr;
    const verify::EventMatch* landing = nullptr;
    bool rear = false, front = false;
    for (const verify::EventMatch& m : e.matches) {
      if (!replay.onGround(m)) continue;
      const std::string& contact = r.contacts[static_cast<std::size_t>(m.optimised.contact)];
      if (m.optimised.kind == verify::ContactEvent::Touchdown && m.optimised.t > replay.goal) {
        rear = rear || (contact == "rear_wheel" && m.matched);
        front = front || (contact == "front_wheel" && m.matched);
      }
      if (m.optimised.kind != verify::ContactEvent::Impact) continue;
      if (contact == "tail" && m.optimised.t < replay.goal && strike == nullptr) strike = &m;
      if (contact != "tail" && m.optimised.t > replay.goal && landing == nullptr) landing = &m;
    }
    ASSERT_NE(strike, nullptr) << "the optimised trajectory strikes the tail before the air goal";
    ASSERT_NE(landing, nullptr) << "the optimised trajectory lands on a wheel after the air goal";
    EXPECT_TRUE(strike->matched) << engine << ": the tail strike at " << strike->optimised.t << " s";
    EXPECT_TRUE(landing->matched) << engine << ": the landing at " << landing->optimised.t << " s";
    std::cout << GetParam() << ", " << engine << ": the tail strike at " << strike->optimised.t << " s, replayed "
              << strike->dt << " s from it; the landing of " << r.contacts[static_cast<std::size_t>(landing->optimised.contact)]
              << " at " << landing->optimised.t << " s, " << landing->dt << " s; largest deviation " << e.max_position_deviation
              << " at t = " << e.t_max_position_deviation << " s\n";
    EXPECT_TRUE(rear && front) << engine << ": both wheels touch down after the air goal";
  }
}

class OllieReplayedClosely : public OllieSolution {};

// And where the element-by-element replay holds to the end (ollie_assist_0.5; not the paper's
// problem, whose back foot's last landing on the deck the engines resolve otherwise than the
// optimiser: README), every one of the optimised impacts on the ground recurs within
// the match window and every coordinate stays within 0.1 m or rad of the optimised one.
TEST_P(OllieReplayedClosely, EveryImpactOnTheGroundRecursAndNoCoordinateStrays) {
  const OllieReplay& replay = replayOllie(GetParam(), transcription(), solution_->x);
  ASSERT_EQ(replay.result.engines.size(), 2u);
  for (const verify::EngineReplay& e : replay.result.engines) {
    const std::string engine = verify::engineName(e.engine);
    for (const verify::EventMatch& m : e.matches) {
      if (!replay.onGround(m) || m.optimised.kind != verify::ContactEvent::Impact) continue;
      EXPECT_TRUE(m.matched) << engine << ": the impact of "
                             << replay.result.contacts[static_cast<std::size_t>(m.optimised.contact)] << " at "
                             << m.optimised.t << " s";
    }
    std::cout << GetParam() << ", " << engine << ": largest deviation " << e.max_position_deviation << " at t = "
              << e.t_max_position_deviation << " s, penetration " << e.max_penetration << " m\n";
    EXPECT_LT(e.max_position_deviation, 0.1) << engine;
  }
}

INSTANTIATE_TEST_SUITE_P(Benchmarks, OllieReplayedClosely, ::testing::Values("ollie_assist_0.5"));

// The lowest row of the frame's drawing (surfaces and shadows off: the board and the rider).
int lowestDrawnRow(const std::vector<std::uint8_t>& rgb, int width, int height, const Eigen::Vector3f& background) {
  for (int y = height - 1; y >= 0; --y) {
    const std::vector<std::uint8_t> row(rgb.begin() + static_cast<long>(y) * width * 3,
                                        rgb.begin() + static_cast<long>(y + 1) * width * 3);
    if (saltus::testing::nonBackground(row, width, 1, background).pixels > 0) return y;
  }
  return -1;
}

// Drawn from the side (the bodies alone), the board stands on the ground at the start and is in
// the air at the air goal's mesh point: the drawing's lowest pixel at the ground's projected row,
// then above it by most of the wheels' clearance.
TEST_P(OllieSolution, DrawnFromTheSideTheBoardIsInTheAirAtTheGoal) {
  SideView view(solutionDir(GetParam()), 320, 240, 100);
  const saltus::RenderInput& input = view.input;
  const render::AnimationOptions& options = view.options;
  const render::Animation& animation = view.animation;
  const render::RenderSettings& settings = view.settings;
  render::Renderer& renderer = view.renderer;
  double goal = -1;  // [20, 0], the air goal's mesh point: both wheels at least 0.2 m up
  for (const collocation::Sample& s : collocation::trajectory(transcription(), solution_->x))
    if (s.element == 19 && s.point == 0) goal = s.t;
  ASSERT_GT(goal, 0);
  int at_goal = 0;
  for (int k = 0; k < animation.frames(); ++k)
    if (std::abs(animation.time(k) - goal) < std::abs(animation.time(at_goal) - goal)) at_goal = k;
  const int board_x = input.scene.model.coordinateIndex("board_x");
  double above[2] = {0, 0}, clearance[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const int frame = k == 0 ? 0 : at_goal;
    render::FrameContent content = animation.content(frame);
    content.arrows.clear();  // the contact forces' arrows and the impulses' markers: the bodies alone
    content.markers.clear();
    renderer.draw(animation.camera(frame), content);
    const int lowest = lowestDrawnRow(renderer.rgb(), options.width, options.height, settings.background);
    ASSERT_GE(lowest, 0) << "frame " << frame << ": something is drawn";
    const Eigen::VectorXd q = input.trajectory->q(animation.time(frame));
    const Eigen::Vector3d under(q[board_x], 0, 0), up_there(q[board_x], 0, 0.2);
    const render::Camera camera = animation.camera(frame);
    const double ground = projectedRow(camera, under, options.height);
    clearance[k] = ground - projectedRow(camera, up_there, options.height);  // 0.2 m in pixels
    above[k] = ground - (lowest + 1);  // the drawing's bottom edge above the ground's row [pixels]
  }
  std::cout << GetParam() << ": the drawing's lowest pixel " << above[0] << " pixels above the ground at the start, "
            << above[1] << " at the air goal (t = " << animation.time(at_goal) << " s; 0.2 m is " << clearance[1]
            << " pixels)\n";
  EXPECT_LT(std::abs(above[0]), 0.25 * clearance[0]);  // the wheels' near side projects a little lower
  EXPECT_GT(above[1], 0.6 * clearance[1]);
}

INSTANTIATE_TEST_SUITE_P(Benchmarks, OllieSolution, ::testing::Values("ollie_assist_0.5", "ollie_impulsive"));

}  // namespace
