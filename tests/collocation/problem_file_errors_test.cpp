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
#include "tests/support/problem_errors.hpp"

// A namespace of its own: the unity build may join this file with problem_file_test.cpp.
namespace saltus::collocation::problem_file_errors {
namespace {

// Bad input: the message names the file, the line marked `# <-- error` in the fixture, the key
// path and what was expected.
using testing::expectProblemError;

TEST(ProblemFileErrors, SceneKeyBesideASceneFile) {
  expectProblemError("scene_reference_with_model.yaml", "model", {"the scene comes from 'skateboard'", "none of its keys"});
}
TEST(ProblemFileErrors, SceneFileThatDoesNotExist) {
  expectProblemError("scene_reference_missing.yaml", "scene", {"skateborad", "did you mean 'skateboard'"});
}
TEST(ProblemFileErrors, ParameterThatShadowsTheScenes) {
  expectProblemError("scene_reference_shadow.yaml", "parameters.friction", {"'friction' is a parameter of", "skateboard.yaml"});
}
TEST(ProblemFileErrors, UnknownKey) {
  expectProblemError("unknown_key.yaml", "mesh.h_mx", {"unknown key 'h_mx'", "did you mean 'h_max'", "expected one of: N, P"});
}
TEST(ProblemFileErrors, QuaternionBaseIsRefused) {
  expectProblemError("quaternion_base.yaml", "base", {"quaternion base", "use base: free"});
}
TEST(ProblemFileErrors, UnknownTopLevelKey) {
  expectProblemError("unknown_top_key.yaml", "constraint", {"unknown key 'constraint'", "did you mean 'constraints'"});
}
TEST(ProblemFileErrors, ElementOutOfRange) {
  expectProblemError("at_out_of_range.yaml", "constraints[1].at", {"element 21 is not in [1, 20]", "numbered from 1"});
}
TEST(ProblemFileErrors, PointOutOfRange) {
  expectProblemError("point_out_of_range.yaml", "hints[0].at", {"point 5 is not in [0, 4]"});
}
TEST(ProblemFileErrors, RangeThatRunsBackwards) {
  expectProblemError("range_backwards.yaml", "constraints[0].to", {"[5, 1] comes before from: [5, 2]"});
}
TEST(ProblemFileErrors, RangeAndAtTogether) {
  expectProblemError("range_and_at.yaml", "constraints[0].at", {"either at: [n, p] or from: [n, p] and to: [n, p]"});
}
TEST(ProblemFileErrors, SurfaceStepNotAtAMeshPoint) {
  expectProblemError("surface_step_not_mesh_point.yaml", "surface_velocity.belt[1].at", {"[n, 0]", "got point 2"});
}
TEST(ProblemFileErrors, UnknownCoordinate) {
  expectProblemError("unknown_coordinate.yaml", "final.q.zz", {"unknown coordinate 'zz'", "did you mean 'z'", "x, z"});
}
TEST(ProblemFileErrors, UnknownContactInGap) {
  expectProblemError("unknown_contact.yaml", "constraints[0].gap.bal", {"unknown contact 'bal'", "did you mean 'ball'"});
}
TEST(ProblemFileErrors, MissingN) {
  expectProblemError("missing_n.yaml", "mesh.N", {"missing required key 'N'"});
}
TEST(ProblemFileErrors, BadP) {
  expectProblemError("bad_p.yaml", "mesh.P", {"[1, 9]", "got 12"});
}
TEST(ProblemFileErrors, TimeScheduledSurfaceNeedsSurfaceVelocity) {
  expectProblemError("time_scheduled_surface.yaml", "surfaces[0].velocity_schedule[1].time",
              {"surface 'belt'", "t = 0.1 s", "element lengths are variables", "surface_velocity.belt"});
}
TEST(ProblemFileErrors, DurationRefused) {
  expectProblemError("duration.yaml", "duration", {"no fixed duration", "mesh.total_time"});
}
TEST(ProblemFileErrors, InputRefused) {
  expectProblemError("input.yaml", "input", {"no constant input", "inputs"});
}
TEST(ProblemFileErrors, BoundOnAnUnactuatedCoordinate) {
  expectProblemError("not_an_input.yaml", "bounds.u.z", {"'z' is not actuated", "the inputs are: x"});
}
TEST(ProblemFileErrors, LowerAboveUpper) {
  expectProblemError("bad_range.yaml", "bounds.q.x", {"lower bound 1 exceeds the upper bound -1"});
}
TEST(ProblemFileErrors, UnreachableTotalTime) {
  expectProblemError("unreachable_total_time.yaml", "mesh.total_time.at_least", {"cannot be reached", "N h_max = 0.2"});
}
TEST(ProblemFileErrors, UnknownSurface) {
  expectProblemError("unknown_surface.yaml", "surface_velocity.groud", {"unknown surface 'groud'", "did you mean 'ground'"});
}


}  // namespace
}  // namespace saltus::collocation::problem_file_errors
