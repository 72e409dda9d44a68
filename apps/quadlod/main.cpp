// quadlod command-line tool: dispatches to one subcommand (see commands.h, README "CLI reference").
#include "commands.h"

#include "quadlod/io.h"

#include <cstdio>
#include <exception>
#include <new>
#include <vector>

namespace quadlod::cli {

int fail(const std::string& message) {
  std::fprintf(stderr, "quadlod: %s\n", message.c_str());
  return kExitBadInput;
}

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  if (std::filesystem::equivalent(a, b, ec)) return true;
  return std::filesystem::weakly_canonical(a, ec) == std::filesystem::weakly_canonical(b, ec);
}

}  // namespace quadlod::cli

int main(int argc, char** argv) {
  using namespace quadlod::cli;
  // An interrupted run leaves no temp file behind and the previous output intact (issue 23).
  quadlod::install_interrupt_cleanup();
  CLI::App app{"quadlod — quad-dominant mesh reduction that keeps edge loops"};
  app.require_subcommand(1);
  app.fallthrough();  // global flags (-q) are accepted after the subcommand too
  app.set_version_flag("--version", "quadlod 0.1.0");
  GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "No progress output on stderr");

  const std::vector<Command> commands = {
      add_simplify(app, global),
      add_info(app, global),
      add_eval(app, global),
      add_analyze(app, global),
      add_generate(app, global),
#ifdef QUADLOD_HTML_REPORT
      add_report(app, global),
#endif
      add_lod(app, global),
      add_batch(app, global),
  };

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }
  try {
    for (const Command& command : commands)
      if (command.sub->parsed()) return command.run();
  } catch (const std::bad_alloc&) {
    // Not a bug but a limit of the machine: one line and the bad-input code, as --max-memory.
    std::fprintf(stderr, "quadlod: out of memory (the input is too large for this machine; see --max-memory)\n");
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "quadlod: internal error: %s\n", e.what());
    return kExitInternal;
  }
  return kExitUsage;
}
