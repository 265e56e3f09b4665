// A URDF's text before urdfdom (dynamics/urdf_text.hpp): numbers a double cannot hold, DTDs,
// and where elements are, with their attributes as written.
#include "dynamics/urdf_text.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "dynamics/builder.hpp"
#include "dynamics/urdf.hpp"
#include "tests/support/errors.hpp"

namespace saltus::dynamics {
namespace {

// The ModelError message of f ("" when it throws none: the expectations then fail).
std::string textErrorOf(const std::function<void()>& f) { return saltus::testing::messageOf<ModelError>(f); }

#ifndef EXPECT_HAS
#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)
#endif

// One moving link on line 5 (mass) and 6 (inertia), the joint from line 8, its axis on line 10.
std::string oneJointRobot(const std::string& mass, const std::string& axis = "0 0 1", const std::string& effort = "10") {
  return "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n  <link name=\"base\"/>\n  <link name=\"l1\"><inertial>\n"
         "    <mass value=\"" + mass + "\"/>\n"
         "    <inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/>\n  </inertial></link>\n"
         "  <joint name=\"j\" type=\"revolute\">\n    <parent link=\"base\"/><child link=\"l1\"/>\n"
         "    <axis xyz=\"" + axis + "\"/>\n"
         "    <limit lower=\"-1\" upper=\"1\" effort=\"" + effort + "\" velocity=\"1\"/>\n  </joint>\n</robot>\n";
}

// A number that a double cannot hold is refused as written, with its line: urdfdom would read
// 1e-400 as 0 and 1e400 as inf, and the mass check would then quote a value never written.
TEST(UrdfText, NumbersOutOfTheRangeOfADoubleAreRefusedAsWritten) {
  EXPECT_NO_THROW(UrdfText(oneJointRobot("2.5"), "r.urdf"));
  std::string what = textErrorOf([] { UrdfText(oneJointRobot("1e-400"), "r.urdf"); });
  EXPECT_EQ(what.rfind("r.urdf:5: <mass value=\"1e-400\">: '1e-400' is out of the range of a double (it would be read as 0)", 0), 0u) << what;
  what = textErrorOf([] { UrdfText(oneJointRobot("-1e400"), "r.urdf"); });
  EXPECT_HAS(what, "'-1e400' is out of the range of a double (it would be read as infinite)");
  what = textErrorOf([] { UrdfText(oneJointRobot("2", "1e999 0 0"), "r.urdf"); });
  EXPECT_EQ(what.rfind("r.urdf:10: <axis xyz=\"1e999 0 0\">", 0), 0u) << what;
  // A million digits: refused, and the message stays short.
  what = textErrorOf([] { UrdfText(oneJointRobot(std::string(1000000, '7')), "r.urdf"); });
  EXPECT_HAS(what, "out of the range of a double");
  EXPECT_LT(what.size(), 400u);
  // A subnormal converts to itself; words and names are not numbers.
  EXPECT_NO_THROW(UrdfText(oneJointRobot("1e-320"), "r.urdf"));
  EXPECT_NO_THROW(UrdfText(oneJointRobot("2", "0 0 1", "e400"), "r.urdf"));
}

// urdfdom does not expand entities: a DTD is refused at its line (a billion-laughs file
// would otherwise be reported as "no robot element").
TEST(UrdfText, ADocumentTypeWithDeclarationsIsRefused) {
  const std::string dtd = "<?xml version=\"1.0\"?>\n<!DOCTYPE robot [\n<!ENTITY a \"aaaa\">\n]>\n<robot name=\"&a;\"/>\n";
  const std::string what = textErrorOf([&] { UrdfText(dtd, "b.urdf"); });
  EXPECT_EQ(what.rfind("b.urdf:2: a DTD with declarations", 0), 0u) << what;
  EXPECT_NO_THROW(UrdfText("<!DOCTYPE robot>\n<robot name=\"r\"/>\n", "plain.urdf"));  // no declarations
}

TEST(UrdfText, WhereAndWrittenFindElementsByOwnerAndPath) {
  const std::string xml = oneJointRobot("2.5", "0 1e-320 0");
  const UrdfText text(xml, "r.urdf");
  EXPECT_EQ(text.where("link", "l1", "inertial/mass"), "r.urdf:5");
  EXPECT_EQ(text.where("link", "l1", "inertial/inertia"), "r.urdf:6");
  EXPECT_EQ(text.where("joint", "j"), "r.urdf:8");
  EXPECT_EQ(text.where("joint", "j", "axis"), "r.urdf:10");
  EXPECT_EQ(text.where("joint", "j", "calibration"), "r.urdf:8");  // missing child: the owner's line
  EXPECT_EQ(text.where("joint", "nope"), "r.urdf");                 // missing owner: the file
  EXPECT_EQ(text.written("joint", "j", "axis"), "<axis xyz=\"0 1e-320 0\"/>");
  EXPECT_EQ(text.written("link", "l1", "inertial/mass"), "<mass value=\"2.5\"/>");
  EXPECT_EQ(text.written("link", "nope", "inertial/mass"), "");
}

// Through the reader: the checks of links and joints say the line and quote the element.
TEST(UrdfText, ReaderChecksQuoteTheElementAsWritten) {
  std::string what = textErrorOf([] { loadUrdfString(oneJointRobot("0"), BaseType::Fixed, "r.urdf"); });
  EXPECT_EQ(what.rfind("r.urdf:5: link 'l1': mass must be positive", 0), 0u) << what;
  EXPECT_HAS(what, "written <mass value=\"0\"/>");
  // non-zero as written, but its length underflows: no direction to normalise
  what = textErrorOf([] { loadUrdfString(oneJointRobot("1", "1e-320 0 0"), BaseType::Fixed, "r.urdf"); });
  EXPECT_EQ(what.rfind("r.urdf:10: joint 'j': axis must be a non-zero vector", 0), 0u) << what;
  EXPECT_HAS(what, "<axis xyz=\"1e-320 0 0\"/>");
  what = textErrorOf([] { loadUrdfString(oneJointRobot("1", "0 0 0"), BaseType::Fixed, "r.urdf"); });
  EXPECT_HAS(what, "r.urdf:10: joint 'j': axis");
  what = textErrorOf([] { loadUrdfString(oneJointRobot("1", "0 0 1", "-3"), BaseType::Fixed, "r.urdf"); });
  EXPECT_EQ(what.rfind("r.urdf:11: joint 'j': <limit effort>", 0), 0u) << what;
}

}  // namespace
}  // namespace saltus::dynamics
