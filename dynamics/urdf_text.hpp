// A URDF's text, checked before urdfdom reads it, and kept to say where its elements are.
//
// urdfdom reports few locations and converts numbers before anyone checks them ("1e-400" becomes
// 0, then "mass must be positive, got 0"). UrdfText refuses what urdfdom would mishandle (binary
// or empty text, deep nesting that overflows TinyXML's recursive parser, a DTD with entities,
// numbers out of the range of a double) naming the file and line, and afterwards answers "which
// line, and what was written" for the reader's own checks of links and joints.
#pragma once

#include <memory>
#include <string>

class TiXmlDocument;
class TiXmlElement;

namespace saltus::dynamics {

class UrdfText {
 public:
  // Checks `xml` (read from `source`, a file name for messages); throws ModelError
  // ("robot.urdf:12: ...") on text that is not a URDF's.
  UrdfText(const std::string& xml, std::string source);
  ~UrdfText();
  UrdfText(const UrdfText&) = delete;
  UrdfText& operator=(const UrdfText&) = delete;

  // Where a link's or joint's element is: `<tag name="owner">`, then the child elements of `path`
  // ("inertial/mass"; empty for the element itself). "robot.urdf:12", or the file name alone when
  // there is no such element.
  std::string where(const std::string& tag, const std::string& owner, const std::string& path = "") const;
  // The same element as written, `<mass value="1e-400"/>` (long values shortened), or "".
  std::string written(const std::string& tag, const std::string& owner, const std::string& path) const;
  // urdfdom's failure message located: the line of the element or value it names in brackets
  // ("Link [a]", "[nan]") and, for "element ixx is not ...", that attribute as written.
  std::string urdfdomLocation(const std::string& summary, std::string* quoted) const;

  const std::string& source() const { return source_; }

 private:
  const TiXmlElement* find(const std::string& tag, const std::string& owner, const std::string& path) const;

  const std::string& xml_;
  std::string source_;
  std::unique_ptr<TiXmlDocument> document_;
};

// The deepest element nesting a URDF may have; the largest file read.
inline constexpr int kMaxXmlDepth = 100;
inline constexpr unsigned long long kMaxUrdfBytes = 64ull << 20;

}  // namespace saltus::dynamics
