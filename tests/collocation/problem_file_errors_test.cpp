// Problem files (collocation/problem_file.hpp) given bad input: one test per kind
// (tests/data/problems/, the offending line marked `# <-- error`), each checking that the message
// names the file, the line and the key path, and says what was expected.
#include "collocation/problem_file.hpp"

#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "saltus/build_paths.hpp"
#include "scene/scenario.hpp"
#include "tests/support/errors.hpp"

// A namespace of its own: the unity build may join this file with problem_file_test.cpp.
namespace saltus::collocation::problem_file_errors {
namespace {

const std::string kDataDir = std::string(SALTUS_SOURCE_DIR) + "/tests/data/problems/";

// Bad input: the message names the file, the line marked `# <-- error` in the fixture, the key
// path and what was expected.
std::string expectError(const std::string& fixture, const std::string& key_path,
                        const std::vector<std::string>& parts) {
  const std::string path = kDataDir + fixture;
  return testing::expectMarkedError<scene::ScenarioError>(path, [&] { loadProblem(path); }, key_path, parts);
}

TEST(ProblemFileErrors, SceneKeyBesideASceneFile) {
  expectError("scene_reference_with_model.yaml", "model", {"the scene comes from 'skateboard'", "none of its keys"});
}
TEST(ProblemFileErrors, SceneFileThatDoesNotExist) {
  expectError("scene_reference_missing.yaml", "scene", {"skateborad", "did you mean 'skateboard'"});
}
TEST(ProblemFileErrors, ParameterThatShadowsTheScenes) {
  expectError("scene_reference_shadow.yaml", "parameters.friction", {"'friction' is a parameter of", "skateboard.yaml"});
}
TEST(ProblemFileErrors, UnknownKey) {
  expectError("unknown_key.yaml", "mesh.h_mx", {"unknown key 'h_mx'", "did you mean 'h_max'", "expected one of: N, P"});
}
TEST(ProblemFileErrors, QuaternionBaseIsRefused) {
  expectError("quaternion_base.yaml", "base", {"quaternion base", "use base: free"});
}
TEST(ProblemFileErrors, UnknownTopLevelKey) {
  expectError("unknown_top_key.yaml", "constraint", {"unknown key 'constraint'", "did you mean 'constraints'"});
}
TEST(ProblemFileErrors, ElementOutOfRange) {
  expectError("at_out_of_range.yaml", "constraints[1].at", {"element 21 is not in [1, 20]", "numbered from 1"});
}
TEST(ProblemFileErrors, PointOutOfRange) {
  expectError("point_out_of_range.yaml", "hints[0].at", {"point 5 is not in [0, 4]"});
}
TEST(ProblemFileErrors, RangeThatRunsBackwards) {
  expectError("range_backwards.yaml", "constraints[0].to", {"[5, 1] comes before from: [5, 2]"});
}
TEST(ProblemFileErrors, RangeAndAtTogether) {
  expectError("range_and_at.yaml", "constraints[0].at", {"either at: [n, p] or from: [n, p] and to: [n, p]"});
}
TEST(ProblemFileErrors, SurfaceStepNotAtAMeshPoint) {
  expectError("surface_step_not_mesh_point.yaml", "surface_velocity.belt[1].at", {"[n, 0]", "got point 2"});
}
TEST(ProblemFileErrors, UnknownCoordinate) {
  expectError("unknown_coordinate.yaml", "final.q.zz", {"unknown coordinate 'zz'", "did you mean 'z'", "x, z"});
}
TEST(ProblemFileErrors, UnknownContactInGap) {
  expectError("unknown_contact.yaml", "constraints[0].gap.bal", {"unknown contact 'bal'", "did you mean 'ball'"});
}
TEST(ProblemFileErrors, MissingN) {
  expectError("missing_n.yaml", "mesh.N", {"missing required key 'N'"});
}
TEST(ProblemFileErrors, BadP) {
  expectError("bad_p.yaml", "mesh.P", {"[1, 9]", "got 12"});
}
TEST(ProblemFileErrors, TimeScheduledSurfaceNeedsSurfaceVelocity) {
  expectError("time_scheduled_surface.yaml", "surfaces[0].velocity_schedule[1].time",
              {"surface 'belt'", "t = 0.1 s", "element lengths are variables", "surface_velocity.belt"});
}
TEST(ProblemFileErrors, DurationRefused) {
  expectError("duration.yaml", "duration", {"no fixed duration", "mesh.total_time"});
}
TEST(ProblemFileErrors, InputRefused) {
  expectError("input.yaml", "input", {"no constant input", "inputs"});
}
TEST(ProblemFileErrors, BoundOnAnUnactuatedCoordinate) {
  expectError("not_an_input.yaml", "bounds.u.z", {"'z' is not actuated", "the inputs are: x"});
}
TEST(ProblemFileErrors, LowerAboveUpper) {
  expectError("bad_range.yaml", "bounds.q.x", {"lower bound 1 exceeds the upper bound -1"});
}
TEST(ProblemFileErrors, UnreachableTotalTime) {
  expectError("unreachable_total_time.yaml", "mesh.total_time.at_least", {"cannot be reached", "N h_max = 0.2"});
}
TEST(ProblemFileErrors, UnknownSurface) {
  expectError("unknown_surface.yaml", "surface_velocity.groud", {"unknown surface 'groud'", "did you mean 'ground'"});
}


}  // namespace
}  // namespace saltus::collocation::problem_file_errors
