// The CLI's subcommands. Each add_*() registers one subcommand on the app and returns the
// function that runs it after parsing; main() only dispatches. Commands do argument handling
// and printing; all work happens in the library.
#pragma once

#include "skin_cli.h"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace quadlod {
struct SimplifyOptions;
}  // namespace quadlod

namespace quadlod::cli {

/// Exit codes, documented in README.md ("CLI reference").
enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 1,     ///< bad command line
  kExitBadInput = 2,  ///< unreadable/invalid input, or an output that cannot be written
  kExitInternal = 3,  ///< a bug: an exception escaped
};

struct GlobalOptions {
  bool quiet = false;  ///< no progress on stderr
};

/// A registered subcommand and the function that runs it once its options are parsed.
struct Command {
  CLI::App* sub = nullptr;
  std::function<int()> run;
};

Command add_info(CLI::App& app, const GlobalOptions& global);
Command add_eval(CLI::App& app, const GlobalOptions& global);
Command add_generate(CLI::App& app, const GlobalOptions& global);
Command add_simplify(CLI::App& app, const GlobalOptions& global);
Command add_analyze(CLI::App& app, const GlobalOptions& global);
#ifdef QUADLOD_HTML_REPORT
Command add_report(CLI::App& app, const GlobalOptions& global);
#endif
Command add_lod(CLI::App& app, const GlobalOptions& global);
Command add_batch(CLI::App& app, const GlobalOptions& global);

/// `quadlod simplify` on a scene (either side not OBJ / PLY / OFF): read_scene, simplify_scene,
/// write_scene; prints one summary line (cmd_scene.cpp). A skinned scene's meshes are reduced
/// in `poses` of its rig as well as at the bind pose (deformation-sensitive quadrics).
int simplify_scene_file(const std::string& input, const std::string& output, const std::string& report,
                        const SimplifyOptions& options, bool per_mesh, const SkinPoseChoice& poses,
                        const std::string& protect_file = "");  // issue 34: --protect FILE

/// An option whose value is one of an enum's names (the `*_names()` of include/quadlod/
/// simplify.h), stored into `target`: the help lists the names in their order and the default
/// ("TEXT:{shape,paper}=shape"), any other value is a usage error ("--objective: bogus not in
/// {shape,paper}"), as CLI::IsMember on a string option gives them.
template <class E>
CLI::Option* add_choice_option(CLI::App* sub, const std::string& flag, E& target,
                               const std::vector<std::pair<std::string, E>>& names, const std::string& help) {
  std::vector<std::string> keys;
  std::string current;
  for (const auto& [name, value] : names) {
    keys.push_back(name);
    if (value == target) current = name;
  }
  return sub
      ->add_option_function<std::string>(
          flag,
          [&target, names](const std::string& chosen) {
            for (const auto& [name, value] : names)
              if (name == chosen) target = value;
          },
          help)
      ->check(CLI::IsMember(keys))
      ->default_str(current);
}

/// Prints "quadlod: message" on stderr and returns kExitBadInput.
int fail(const std::string& message);

/// True when a and b name the same file (existing or not); used to refuse overwriting an input.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

}  // namespace quadlod::cli
