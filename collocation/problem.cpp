#include "collocation/problem.hpp"

#include <stdexcept>

#include "scene/yaml_reader.hpp"

namespace saltus::collocation {

const char* toString(Method m) {
  switch (m) {
    case Method::Impulsive: return "impulsive";
    case Method::Continuous: return "continuous";
    case Method::FirstOrder: return "first-order";
  }
  return "unknown";
}

Method parseMethod(const std::string& name) {
  const std::vector<std::string> names = {"impulsive", "continuous", "first-order"};
  for (Method m : {Method::Impulsive, Method::Continuous, Method::FirstOrder})
    if (name == toString(m)) return m;
  throw std::invalid_argument("unknown method '" + name + "'" + scene::suggestion(name, names) +
                              "; expected one of: " + scene::joinNames(names));
}

}  // namespace saltus::collocation
