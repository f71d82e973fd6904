// Reading and writing object meshes: OFF, Wavefront OBJ and STL (read only).
//
// OFF: an optional `OFF` header, the counts `vertices faces edges`, vertex lines `x y z`, then
// polygon lines `n i1 ... in` (0-based indices, counter-clockwise seen from outside, convex;
// colours after the indices are ignored). A comment after a polygon (`4 0 1 2 3 # top`) names it;
// other `#` comments are ignored. OBJ: `v x y z`, `f a b c ...` (1-based or negative indices,
// `a/t/n` forms accepted), and `g name` / `o name` name the polygons that follow; other statements
// (vt, vn, s, usemtl, mtllib) are ignored. Both are validated as closed meshes (mesh.hpp): any
// mistake throws GeometryError with "file:line: what is wrong". STL, ASCII or binary, is read by
// CGAL's STL reader (identical points become one vertex; the file's normals are ignored, the
// triangles' order of corners gives the orientation, and an inward mesh is turned outward). STL
// triangles have no names and no lines: errors name the file.
//
// Example:
//   Mesh mesh = read_mesh_file("examples/objects/block.off");
//   write_off(mesh, std::cout, "a block");
#pragma once

#include <iosfwd>
#include <string>

#include "spar/geometry/mesh.hpp"

namespace spar::geometry {

// By extension (.off, .obj or .stl, any case).
[[nodiscard]] Mesh read_mesh_file(const std::string& path);
// `source` names the text in error messages (normally the file name).
[[nodiscard]] Mesh parse_off(const std::string& text, const std::string& source);
[[nodiscard]] Mesh parse_obj(const std::string& text, const std::string& source);
// `bytes`: the whole file, ASCII or binary.
[[nodiscard]] Mesh parse_stl(const std::string& bytes, const std::string& source);
// A triangle soup for collision only (robot links' meshes, kinematics/urdf.hpp): a link's mesh
// need not be closed or free of self-crossings (collision.hpp measures distances between any
// triangles), so STL is read as its triangles with identical points welded and degenerate ones
// dropped, nothing more checked; OFF and OBJ as read_mesh_file reads them. Throws GeometryError
// for an unreadable file or one without triangles.
[[nodiscard]] Mesh parse_stl_soup(const std::string& bytes, const std::string& source);
[[nodiscard]] Mesh read_triangle_soup(const std::string& path);
// Writes triangles with their names as comments; `header` lines become leading `#` comments.
void write_off(const Mesh& mesh, std::ostream& out, const std::string& header);

}  // namespace spar::geometry
