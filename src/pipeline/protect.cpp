// Protected regions (issue 34): the weights' sources and checks (include/quadlod/protect.h). The
// pipeline's use of them is in simplify.cpp (pins, point quadrics, passes) and the collapse
// (post/cluster_collapse.h, `protected_vertices`); docs/protect.md has the semantics.
#include "quadlod/protect.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>

namespace quadlod {

std::vector<std::pair<std::string, SimplifyOptions::ProtectChannel>> protect_channel_names() {
  using C = SimplifyOptions::ProtectChannel;
  return {{"none", C::None}, {"color:r", C::Red}, {"color:g", C::Green}, {"color:b", C::Blue}};
}

std::optional<SimplifyOptions::ProtectChannel> parse_protect_channel(const std::string& name) {
  for (const auto& [n, c] : protect_channel_names())
    if (n == name) return c;
  return std::nullopt;
}

const char* to_string(SimplifyOptions::ProtectChannel channel) {
  static const auto names = protect_channel_names();
  for (const auto& [n, c] : names)
    if (c == channel) return n.c_str();
  return "?";
}

ProtectWeightsRead read_protect_weights(const std::string& path, std::size_t expected_vertices) {
  ProtectWeightsRead out;
  std::ifstream in(path);
  if (!in) {
    out.error = path + ": cannot read the protect file";
    return out;
  }
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // CRLF files
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::size_t last = line.find_last_not_of(" \t");
    const std::string text = line.substr(first, last - first + 1);
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (expected_vertices > 0 && out.weights.size() == expected_vertices) {
      out.error = where + "weight for vertex " + std::to_string(out.weights.size()) + ", the mesh has " +
                  std::to_string(expected_vertices) + " vertices";
      out.weights.clear();
      return out;
    }
    char* end = nullptr;
    errno = 0;
    const double w = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(w)) {
      out.error = where + "'" + text + "' is not a number (one weight in [0, 1] per line)";
      out.weights.clear();
      return out;
    }
    if (w < 0.0 || w > 1.0) {
      out.error = where + "weight " + text + " is outside [0, 1]";
      out.weights.clear();
      return out;
    }
    out.weights.push_back(w);
  }
  if (expected_vertices > 0 && out.weights.size() != expected_vertices) {
    out.error = path + ": " + std::to_string(out.weights.size()) + " weights, the mesh has " +
                std::to_string(expected_vertices) + " vertices";
    out.weights.clear();
  }
  return out;
}

std::vector<double> protect_weights_from_colors(const PolyMesh& mesh, SimplifyOptions::ProtectChannel channel) {
  using C = SimplifyOptions::ProtectChannel;
  if (channel == C::None || mesh.vertex_colors.size() != mesh.positions.size() || mesh.positions.empty()) return {};
  const int k = channel == C::Red ? 0 : channel == C::Green ? 1 : 2;
  std::vector<double> w(mesh.vertex_colors.size());
  for (std::size_t v = 0; v < w.size(); ++v) {
    const double c = mesh.vertex_colors[v][k];
    w[v] = std::isfinite(c) ? std::clamp(c, 0.0, 1.0) : 0.0;
  }
  return w;
}

std::string check_protect_weights(const std::vector<double>& weights, Index vertices) {
  if (weights.empty()) return {};
  if (weights.size() != vertices)
    return std::to_string(weights.size()) + " protect weights for " + std::to_string(vertices) + " vertices";
  for (std::size_t v = 0; v < weights.size(); ++v)
    if (!(weights[v] >= 0.0 && weights[v] <= 1.0))
      return "protect weight of vertex " + std::to_string(v) + " is " + std::to_string(weights[v]) + ", outside [0, 1]";
  return {};
}

std::string split_protect_weights(const std::vector<double>& weights, const std::vector<Index>& sizes,
                                  std::vector<std::vector<double>>& per_mesh) {
  std::size_t total = 0;
  for (Index n : sizes) total += n;
  per_mesh.clear();
  if (weights.size() != total)
    return std::to_string(weights.size()) + " protect weights for " + std::to_string(total) + " vertices in " +
           std::to_string(sizes.size()) + " meshes";
  std::size_t at = 0;
  for (Index n : sizes) {
    per_mesh.emplace_back(weights.begin() + std::ptrdiff_t(at), weights.begin() + std::ptrdiff_t(at + n));
    at += n;
  }
  return {};
}

}  // namespace quadlod
