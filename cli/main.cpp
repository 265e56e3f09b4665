// saltus: the command-line front end. Each subcommand lives in its own file and registers
// itself through an add*Command function (cli/common.hpp); this file parses, dispatches and
// turns errors into messages and exit codes.
#include <exception>
#include <string>
#include <iostream>
#include <vector>

#include "cli/common.hpp"
#include "dynamics/builder.hpp"
#include "scene/cleanup.hpp"

#ifndef SALTUS_VERSION
#define SALTUS_VERSION "unknown"
#endif

int main(int argc, char** argv) {
  using namespace saltus;
  CLI::App app{"Saltus: rigid multibody systems with impacts and friction."};
  app.name("saltus");
  app.set_version_flag("--version", "saltus " SALTUS_VERSION);
  app.require_subcommand(1);

  const std::vector<cli::Command> commands = {
      cli::addInspectCommand(app),
      cli::addSimulateCommand(app),
      cli::addOptimizeCommand(app),
      cli::addBenchCommand(app),
      cli::addRenderCommand(app),
      cli::addReplayCommand(app),
      cli::addRunCommand(app),
      cli::addSweepCommand(app),
  };

  // CLI11 would call a missing or unknown command "required"; name them instead.
  std::string known;
  for (const cli::Command& command : commands) known += (known.empty() ? "" : ", ") + command.app->get_name();
  if (argc < 2) {
    std::cerr << "saltus: no command given (commands: " << known << ")\nRun 'saltus --help' for usage.\n";
    return 2;
  }
  if (argv[1][0] != '-') {
    const std::string word = argv[1];
    bool found = false;
    for (const cli::Command& command : commands) found = found || command.app->get_name() == word;
    if (!found) {
      std::cerr << "saltus: unknown command '" << word << "' (commands: " << known
                << ")\nRun 'saltus --help' for usage.\n";
      return 2;
    }
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help, --version
    std::string help = "saltus --help";
    for (const cli::Command& command : commands)
      if (command.app->parsed()) help = "saltus " + command.app->get_name() + " --help";
    std::cerr << "saltus: " << e.what() << "\nRun '" << help << "' for usage.\n";
    return 2;
  }

  // SIGINT, SIGTERM: children stopped, temporaries removed, exit 130 / 143 (scene/cleanup.hpp).
  scene::installInterruptCleanup("saltus");
  for (const cli::Command& command : commands) {
    if (!command.app->parsed()) continue;
    int code = 1;
    try {
      code = command.run();
    } catch (const cli::UsageError& e) {
      scene::yieldToInterrupt();  // a failure the interrupt caused is reported as the interrupt
      std::cerr << "saltus: " << e.what() << "\nRun 'saltus " << command.app->get_name()
                << " --help' for usage.\n";
      code = 2;
    } catch (const std::exception& e) {
      scene::yieldToInterrupt();
      std::cerr << "saltus: " << e.what() << "\n";
      code = 1;
    }
    scene::yieldToInterrupt();
    return code;
  }
  return 2;  // unreachable: require_subcommand(1)
}
