// Issue 34 (docs/protect.md): the protect options shared by simplify, lod and batch.
#pragma once

#include "commands.h"

#include "quadlod/simplify.h"

#include <string>

namespace quadlod::cli {

/// --protect FILE, --protect-from CHANNEL, --protect-strength, --protect-importance on `sub`;
/// the channel and the two numbers go straight into `options`, the file name into `file`.
void add_protect_options(CLI::App* sub, std::string& file, SimplifyOptions& options);

/// Reads `file` (if any) into options.protect_weights; `vertices` > 0: the count it must hold
/// (0: any, checked later against a scene's meshes). "" or the one-line error naming the file.
std::string load_protect_file(const std::string& file, SimplifyOptions& options, std::size_t vertices);

}  // namespace quadlod::cli
