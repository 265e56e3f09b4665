// Fuzzes the URDF model reader: dynamics::readUrdfString (the XML nesting check checkXmlNesting,
// urdfdom's parse with its messages captured, the loop scan, the link and joint conversion and
// their checks), then ModelBuilder::build of what it read, with a fixed and with a free base.
// Documented failure for bad input: dynamics::ModelError. Anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "dynamics/builder.hpp"
#include "dynamics/urdf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saltus::dynamics;
  const std::string xml(reinterpret_cast<const char*>(data), size);
  try {
    const ModelBuilder builder = readUrdfString(xml, "fuzz.urdf");
    (void)builder.build(BaseType::Fixed);
    (void)builder.build(BaseType::Free);
  } catch (const ModelError&) {
  }
  return 0;
}
