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

  // An empty value ("--N ''", "--seed-kind=") would be taken as the default by CLI11: refused.
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool empty_next = a.size() > 1 && a[0] == '-' && a.find('=') == std::string::npos && i + 1 < argc && argv[i + 1][0] == '\0';
    if ((a.rfind("--", 0) == 0 && a.back() == '=') || empty_next) {
      std::cerr << "saltus: " << a.substr(0, a.find('=')) << ": expected a value, got an empty string\n"
                << "Run 'saltus --help' for usage.\n";
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ConversionError& e) {
    // CLI11 says "Could not convert: --seed = -1"; say what was expected.
    std::string command = "saltus", message = e.what();
    const std::string prefix = "Could not convert: ";
    const std::size_t eq = message.find(" = ");
    if (message.rfind(prefix, 0) == 0 && eq != std::string::npos) {
      const std::string name = message.substr(prefix.size(), eq - prefix.size());
      const std::string value = message.substr(eq + 3);
      std::string type;
      for (const cli::Command& c : commands) {
        if (!c.app->parsed()) continue;
        command = "saltus " + c.app->get_name();
        for (const CLI::Option* o : c.app->get_options())
          if (o->check_name(name)) type = o->get_type_name();
      }
      const std::string expected = type == "UINT"    ? "a whole number of 0 or more"
                                   : type == "INT"   ? "a whole number"
                                   : type == "FLOAT" ? "a number"
                                                     : "a value of type " + type;
      message = name + ": expected " + expected + ", got '" + value + "'";
    }
    std::cerr << "saltus: " << message << "\nRun '" << command << " --help' for usage.\n";
    return 2;
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
      std::cerr << "saltus: " << cli::withValueAsWritten(*command.app, e.what()) << "\nRun 'saltus " << command.app->get_name()
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
