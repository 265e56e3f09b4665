// Writing an output file so that a reader never sees it half-written: the text goes to a
// temporary file beside the target, which is then renamed onto it. A target that exists and is
// not a regular file (a symlink such as /dev/stdout, a device, a folder) is refused, never replaced.
#pragma once

#include <string>

namespace saltus::scene {

// Throws std::runtime_error naming the file and the reason.
void writeFileAtomically(const std::string& path, const std::string& text);

}  // namespace saltus::scene
