// Writing an output file so that a reader never sees it half-written: the content goes to a
// temporary file beside the target (same folder, so the rename cannot cross file systems), which
// is flushed to the disk and then renamed onto it. A target that exists and is not a regular file
// is never replaced: a character device or a pipe (/dev/null, /dev/stdout, through a symlink or
// not) is written into directly; anything else (a folder, a symlink to a file) is refused. Every writer of
// an output file goes through here: the time-stepper's trajectory, the optimiser's solution files,
// PNG frames and the encoder's video.
#pragma once

#include <cstdio>
#include <string>

namespace saltus::scene {

class AtomicFile {
 public:
  // Stream: this process writes the temporary file through stream().
  // External: another program writes temporaryPath() (an encoder); commit() only renames it.
  enum class Mode { Stream, External };

  // Checks the target and, in Stream mode, opens the temporary file for writing; `suffix` ends the
  // temporary name (programs that pick a format by extension). Throws std::runtime_error naming
  // the target and the reason.
  explicit AtomicFile(std::string path, Mode mode = Mode::Stream, const std::string& suffix = "");
  ~AtomicFile();  // removes the temporary file unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::FILE* stream() const { return file_; }  // null in External mode and after commit()
  const std::string& path() const { return path_; }
  const std::string& temporaryPath() const { return tmp_path_; }

  // Stream mode: flushes, fsyncs and closes the stream (a write error anywhere before is reported
  // here); then renames the temporary file onto the target. Throws std::runtime_error naming the
  // target.
  void commit();

 private:
  std::string path_, tmp_path_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
  bool direct_ = false;  // a character device or a pipe (/dev/null, /dev/stdout): written in place
};

// Whether `path` is written in place rather than replaced: an existing character device or pipe,
// or a descriptor path (/dev/stdout, /dev/fd/N, /proc/self/fd/N) whatever it leads to.
bool writtenInPlace(const std::string& path);

// The whole of `text` as the file `path`, through an AtomicFile.
void writeFileAtomically(const std::string& path, const std::string& text);

}  // namespace saltus::scene
