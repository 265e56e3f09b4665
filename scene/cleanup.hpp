// What an interrupted command leaves behind: nothing. The process keeps a list of its temporary
// files and folders (AtomicFile registers each one) and of the child processes it started (an
// encoder, a chart script, the steps of `saltus run`). A program that installs the interrupt
// cleanup (the saltus command; not a library user, not Python) answers SIGINT and SIGTERM by
// stopping its children's process groups, removing the temporaries and exiting with 128 + the
// signal (130, 143). A temporary left by a process that was killed outright (SIGKILL, a power
// cut) is removed by the next saltus process that writes into the same folder.
//
// Temporaries are named "<target>.tmp-<pid>[suffix]": the pid says whether the writer still lives.
#pragma once

#include <spawn.h>
#include <sys/types.h>

#include <string>
#include <vector>

namespace saltus::scene {

// The temporary name of `target` for this process ("<target>.tmp-<pid><suffix>").
std::string temporaryName(const std::string& target, const std::string& suffix = "");

// Removed on an interrupt while registered. Registration comes before the file or folder is
// created, so that an interrupt in between cannot leave it behind.
void registerTemporary(const std::string& path);
void forgetTemporary(const std::string& path);

// A registered temporary for the lifetime of the object (removed, file or folder, on destruction
// unless kept).
class ScopedTemporary {
 public:
  explicit ScopedTemporary(std::string path);
  ~ScopedTemporary();
  ScopedTemporary(const ScopedTemporary&) = delete;
  ScopedTemporary& operator=(const ScopedTemporary&) = delete;
  const std::string& path() const { return path_; }
  void keep();  // renamed into place by the owner: no longer removed

 private:
  std::string path_;
  bool keep_ = false;
};

// Starts `program` (a path, or a name looked up in PATH) as the leader of a new process group with
// the default dispositions of SIGINT, SIGTERM and SIGPIPE and SALTUS_PARENT_PID set (a saltus
// child stops when this process dies, even by SIGKILL), and registers it, so that an interrupt
// stops it and everything it started. An empty `environment` passes this process's own;
// `actions` may be null. Returns the pid; throws
// std::runtime_error naming the program when it cannot be started.
// How an interrupt stops a child: Terminate (SIGTERM, SIGKILL after 3 s: a saltus child cleans up
// itself) or Kill (SIGKILL at once: a program whose output is all temporary, such as ffmpeg, which
// on SIGTERM waits for the rest of its input).
enum class ChildStop { Terminate, Kill };
pid_t spawnChild(const std::string& program, const std::vector<std::string>& arguments,
                 const std::vector<std::string>& environment, const posix_spawn_file_actions_t* actions,
                 ChildStop stop = ChildStop::Terminate);
// Waits for a child started by spawnChild (retrying on EINTR) and forgets it; returns the wait status.
int waitChild(pid_t pid);

// Installs the SIGINT/SIGTERM cleanup described above for this process; `program` starts the
// message printed on an interrupt ("saltus: interrupted by SIGINT; ...").
void installInterruptCleanup(const std::string& program);

// When an interrupt is being handled, waits for its cleanup to end the process (the main thread
// calls it before exiting, so that a failure the interrupt caused does not exit first with its own
// status); otherwise returns at once.
void yieldToInterrupt();

// Removes the entries of `folder` named "<name>.tmp-<pid>[...]" whose process no longer exists;
// returns their paths. Done once per folder and process by AtomicFile.
std::vector<std::string> removeStaleTemporaries(const std::string& folder);

}  // namespace saltus::scene
