// Shapes built in code for tests, and small queries on them.
#ifndef NEURALMESH_TESTS_TESTING_SHAPES_H_
#define NEURALMESH_TESTS_TESTING_SHAPES_H_

#include <cstddef>
#include <vector>

#include "core/mesh.h"
#include "core/triangle_mesh.h"

namespace neuralmesh::testing {

// A unit icosahedron subdivided `levels` times and projected to the sphere of `radius`:
// 10 * 4^levels + 2 vertices, closed, genus 0.
TriangleMesh Icosphere(int levels, double radius = 1.0);

// A regular triangulated grid of (nx+1) x (ny+1) vertices on the square [0,1]^2 at z = 0:
// an open disc with one boundary loop.
TriangleMesh GridPatch(int nx, int ny);

// Sizes of the boundary loops of `mesh` over its live half-edges, sorted ascending.
std::vector<size_t> BoundaryLoopSizes(const Mesh& mesh);

// Converts and aborts the test on failure.
Mesh MustToMesh(const TriangleMesh& triangles);

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_SHAPES_H_
