// Shapes built in code for tests.
#ifndef NEURALMESH_TESTS_TESTING_SHAPES_H_
#define NEURALMESH_TESTS_TESTING_SHAPES_H_

#include "core/mesh.h"
#include "core/triangle_mesh.h"

namespace neuralmesh::testing {

// A unit icosahedron subdivided `levels` times and projected to the sphere of `radius`:
// 10 * 4^levels + 2 vertices, closed, genus 0.
TriangleMesh Icosphere(int levels, double radius = 1.0);

// A regular triangulated grid of (nx+1) x (ny+1) vertices on the square [0,1]^2 at z = 0:
// an open disc with one boundary loop.
TriangleMesh GridPatch(int nx, int ny);

// Converts and aborts the test on failure.
Mesh MustToMesh(const TriangleMesh& triangles);

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_SHAPES_H_
