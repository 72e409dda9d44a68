// Issue 34: the protect options of the CLI (protect_cli.h).
#include "protect_cli.h"

#include "quadlod/protect.h"

namespace quadlod::cli {

void add_protect_options(CLI::App* sub, std::string& file, SimplifyOptions& options) {
  auto* from_file = sub->add_option("--protect", file,
                                    "Protect weights, one per input vertex in [0, 1] (line i = vertex i; '#' lines and "
                                    "blank lines skipped): 1 = keep the vertex exactly and the edges between such "
                                    "vertices, between 0 and 1 = collapses there cost more (docs/protect.md)")
                        ->group("Protect");
  auto* from_colour =
      add_choice_option(sub, "--protect-from", options.protect_channel, protect_channel_names(),
                        "Protect weights from a vertex colour channel (OBJ v x y z r g b, glTF COLOR_0, FBX colours)")
          ->group("Protect");
  from_file->excludes(from_colour);
  from_colour->excludes(from_file);
  sub->add_option("--protect-strength", options.protect_strength,
                  "Shape objective: a vertex of weight w costs strength * w times its area's planes when it moves")
      ->check(CLI::Range(0.0, 1e9))
      ->default_str(std::to_string(default_protect_strength()))
      ->group("Protect");
  sub->add_option("--protect-importance", options.protect_importance,
                  "Paper objective: importance added to an edge per unit of its endpoints' larger weight")
      ->check(CLI::Range(0.0, 1e9))
      ->default_str(std::to_string(default_protect_importance()))
      ->group("Protect");
}

std::string load_protect_file(const std::string& file, SimplifyOptions& options, std::size_t vertices) {
  if (file.empty()) return {};
  ProtectWeightsRead read = read_protect_weights(file, vertices);
  if (!read.ok()) return read.error;
  options.protect_weights = std::move(read.weights);
  return {};
}

}  // namespace quadlod::cli
