// quadlod — the properties the fuzz targets check (see fuzz_checks.h).
#include "fuzz_checks.h"

#include "io/io_common.h"
#include "mesh/connectivity.h"
#include "mesh/validation.h"

#include <algorithm>
#include <cmath>

namespace quadlod::fuzz {

namespace {

const char* format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::Obj: return "fuzz.obj";
    case MeshFormat::Ply: return "fuzz.ply";
    case MeshFormat::Off: return "fuzz.off";
  }
  return "fuzz";
}

ReadResult parse(MeshFormat format, std::string_view bytes, const std::string& name) {
  switch (format) {
    case MeshFormat::Obj: return parse_obj(bytes, name);
    case MeshFormat::Ply: return io_detail::parse_ply(bytes, name);
    case MeshFormat::Off: return io_detail::parse_off(bytes, name);
  }
  return {};
}

bool format(MeshFormat format, const PolyMesh& mesh, const WriteOptions& options, std::string& out,
            std::string& error) {
  switch (format) {
    case MeshFormat::Obj: return io_detail::format_obj(mesh, options, out, error);
    case MeshFormat::Ply: return io_detail::format_ply(mesh, options, out, error);
    case MeshFormat::Off: return io_detail::format_off(mesh, options, out, error);
  }
  return false;
}

// A reader's or the pipeline's error: one line, non-empty.
std::string check_error_line(const std::string& error, const std::string& what) {
  if (error.empty()) return what + ": failed without a message";
  if (error.find('\n') != std::string::npos) return what + ": error message spans lines: " + error;
  return {};
}

std::string check_mesh(const PolyMesh& mesh, const std::string& what) {
  if (std::string layout = mesh.check_layout(); !layout.empty()) return what + ": invalid layout: " + layout;
  if (mesh.num_faces() == 0) return what + ": no faces";
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (!mesh.positions[v].allFinite()) return what + ": vertex " + std::to_string(v) + " is not finite";
  return {};
}

// Write `mesh` in `format` / `encoding`, read it back, compare the counts.
std::string check_round_trip(MeshFormat fmt, const PolyMesh& mesh, PlyEncoding encoding) {
  WriteOptions wo;
  wo.precision = 17;
  wo.ply_encoding = encoding;
  std::string text, error;
  const std::string what = std::string("round trip ") + format_name(fmt) +
                           (fmt == MeshFormat::Ply ? " encoding " + std::to_string(int(encoding)) : "");
  if (!format(fmt, mesh, wo, text, error)) {
    // A writer may refuse what its format cannot hold, with a one-line reason.
    return check_error_line(error, what + " (write)");
  }
  const ReadResult back = parse(fmt, text, format_name(fmt));
  if (!back.ok()) return what + ": the written file does not read back: " + back.error;
  if (back.mesh.num_faces() != mesh.num_faces() || back.mesh.num_vertices() != mesh.num_vertices())
    return what + ": counts changed (" + std::to_string(mesh.num_vertices()) + " vertices, " +
           std::to_string(mesh.num_faces()) + " faces -> " + std::to_string(back.mesh.num_vertices()) + ", " +
           std::to_string(back.mesh.num_faces()) + ")";
  if (back.mesh.corner_vertex != mesh.corner_vertex) return what + ": face corners changed";
  return {};
}

}  // namespace

std::string check_reader(MeshFormat fmt, std::string_view bytes) {
  const std::string name = format_name(fmt);
  const ReadResult r = parse(fmt, bytes, name);
  if (!r.ok()) {
    if (std::string e = check_error_line(r.error, "read"); !e.empty()) return e;
    if (r.error.rfind(name, 0) != 0) return "read: error does not name the file: " + r.error;
    if (r.mesh.num_faces() != 0 || r.mesh.num_vertices() != 0) return "read: failed but returned a mesh: " + r.error;
    return {};
  }
  if (std::string e = check_mesh(r.mesh, "read"); !e.empty()) return e;
  if (fmt == MeshFormat::Ply) {
    for (PlyEncoding enc : {PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian, PlyEncoding::BinaryBigEndian})
      if (std::string e = check_round_trip(fmt, r.mesh, enc); !e.empty()) return e;
    return {};
  }
  return check_round_trip(fmt, r.mesh, PlyEncoding::BinaryLittleEndian);
}

namespace {

struct ByteReader {
  std::string_view bytes;
  std::size_t at = 0;
  bool done() const { return at >= bytes.size(); }
  std::uint8_t u8() { return at < bytes.size() ? static_cast<std::uint8_t>(bytes[at++]) : 0; }
  std::uint16_t u16() {
    const std::uint16_t lo = u8();
    return static_cast<std::uint16_t>(lo | (std::uint16_t{u8()} << 8));
  }
};

}  // namespace

PipelineCase decode_pipeline_case(std::string_view bytes) {
  ByteReader in{bytes};
  PipelineCase c;
  SimplifyOptions& o = c.options;
  o.ratio = (in.u8() + 1) / 256.0;
  const std::uint8_t flags = in.u8();
  o.features = !(flags & 1);
  if (flags & 2) {
    o.objective = SimplifyOptions::Objective::Paper;
    o.time_limit_seconds = 0.0;  // greedy selection: a MIP has no place in a 2 s budget
  }
  o.segmentation = !(flags & 4);
  o.dual_repair = !(flags & 8);
  // At most kMaxPipelinePasses passes (the default plans up to 32 at low ratios): each pass is
  // the whole pipeline again, and a fuzz run wants many inputs more than many passes of one.
  o.max_passes = (flags & 16) ? 1 : kMaxPipelinePasses;
  o.threads = 1;
  o.progress = false;
  const Index nv = 3 + Index{in.u8()};
  c.mesh.positions.reserve(nv);
  for (Index v = 0; v < nv; ++v) {
    const auto x = static_cast<std::int16_t>(in.u16());
    const auto y = static_cast<std::int16_t>(in.u16());
    const auto z = static_cast<std::int16_t>(in.u16());
    c.mesh.positions.emplace_back(x / 256.0, y / 256.0, z / 256.0);
  }
  std::vector<Index> face;
  while (!in.done() && c.mesh.num_faces() < kMaxPipelineFaces) {
    const Index degree = 3 + in.u8() % 8;
    face.clear();
    for (Index k = 0; k < degree; ++k) face.push_back((nv > 256 ? Index{in.u16()} : Index{in.u8()}) % nv);
    // The readers refuse faces that repeat a vertex; the pipeline never sees them.
    std::vector<Index> sorted = face;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) continue;
    c.mesh.add_face(face);
  }
  return c;
}

bool encode_pipeline_case(const PolyMesh& mesh, double ratio, std::uint8_t flags, std::string& out) {
  out.clear();
  if (mesh.num_vertices() < 3 || mesh.num_vertices() > 258 || mesh.num_faces() > kMaxPipelineFaces) return false;
  const auto put16 = [&](std::uint16_t v) {
    out.push_back(static_cast<char>(v & 0xff));
    out.push_back(static_cast<char>(v >> 8));
  };
  out.push_back(static_cast<char>(std::clamp(std::lround(ratio * 256.0) - 1, 0l, 255l)));
  out.push_back(static_cast<char>(flags));
  out.push_back(static_cast<char>(mesh.num_vertices() - 3));
  const double extent = std::max(1e-9, bounding_box(mesh).extent().maxCoeff());
  // Centred and scaled to a box of side 128 (±16384 in units of 1/256, inside int16).
  const double scale = 128.0 * 256.0 / extent;
  const Vec3 centre = 0.5 * (bounding_box(mesh).min + bounding_box(mesh).max);
  for (const Vec3& p : mesh.positions)
    for (int k = 0; k < 3; ++k) put16(static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround((p[k] - centre[k]) * scale))));
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    if (mesh.face_size(f) > 10) return false;
    out.push_back(static_cast<char>(mesh.face_size(f) - 3));
    for (Index v : mesh.face_vertices(f)) {
      if (mesh.num_vertices() > 256) put16(static_cast<std::uint16_t>(v));
      else out.push_back(static_cast<char>(v));
    }
  }
  return true;
}

std::string check_pipeline(std::string_view bytes) {
  const PipelineCase c = decode_pipeline_case(bytes);
  if (c.mesh.num_faces() == 0) return {};
  const SimplifyResult r = simplify(c.mesh, c.options);
  if (!r.ok()) return check_error_line(r.error, "simplify");
  if (std::string e = check_mesh(r.mesh, "simplify output"); !e.empty()) return e;
  if (r.achieved != tri_equivalent_count(r.mesh))
    return "simplify: reports " + std::to_string(r.achieved) + " tri-equivalents, the output has " +
           std::to_string(tri_equivalent_count(r.mesh));
  const MeshStats in = compute_stats(c.mesh, build_connectivity(c.mesh));
  const MeshStats out = compute_stats(r.mesh, build_connectivity(r.mesh));
  if (out.nonmanifold_edges > in.nonmanifold_edges)
    return "simplify: non-manifold edges " + std::to_string(in.nonmanifold_edges) + " -> " +
           std::to_string(out.nonmanifold_edges);
  if (out.repeated_index_faces > in.repeated_index_faces)
    return "simplify: faces using a vertex twice " + std::to_string(in.repeated_index_faces) + " -> " +
           std::to_string(out.repeated_index_faces);
  return {};
}

}  // namespace quadlod::fuzz
