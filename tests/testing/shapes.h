// Shapes built in code for tests, and small queries on them.
#ifndef NEURALMESH_TESTS_TESTING_SHAPES_H_
#define NEURALMESH_TESTS_TESTING_SHAPES_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/mesh.h"
#include "core/point_cloud.h"
#include "core/triangle_mesh.h"

namespace neuralmesh::testing {

// A unit icosahedron subdivided `levels` times and projected to the sphere of `radius`:
// 10 * 4^levels + 2 vertices, closed, genus 0.
TriangleMesh Icosphere(int levels, double radius = 1.0);

// `n` points drawn uniformly from the unit sphere with `seed`, then one stray point at `stray`.
PointCloud UnitSpherePointsAndAStray(size_t n, uint64_t seed, const Vec3f& stray);

// A colour that varies smoothly with position, for the colour tests: each channel is
// 255 * (coordinate + 1) / 2, rounded and clamped, so a unit sphere spans every level.
Rgb ColorOfPosition(const Vec3f& p);

// Icosphere(levels) with each vertex coloured ColorOfPosition.
TriangleMesh ColoredIcosphere(int levels);

// `n` points drawn uniformly from the unit sphere with `seed`, each coloured ColorOfPosition.
PointCloud ColoredUnitSpherePoints(size_t n, uint64_t seed);

// The largest difference of a channel between `color` and ColorOfPosition(`p`).
int ColorError(const Rgb& color, const Vec3f& p);

// For a mesh learned from ColoredUnitSpherePoints: the largest ColorError of a vertex's colour
// against the unit sphere's point nearest the vertex (where the coloured points are; a coarse
// mesh's vertices lie inside the sphere). -1 when the mesh has no colours.
int WorstColorErrorOnTheUnitSphere(const TriangleMesh& mesh);

// A regular triangulated grid of (nx+1) x (ny+1) vertices on the square [0,1]^2 at z = 0:
// an open disc with one boundary loop.
TriangleMesh GridPatch(int nx, int ny);

// A torus round the z axis, tube radius `minor` round a circle of radius `major`, as a grid of
// `along` rings of `around` vertices (vertex i * around + j: ring i, angle j round the tube),
// faces counter-clockwise seen from outside: closed, genus 1.
TriangleMesh TorusGrid(int along, int around, double major, double minor);

// TorusGrid(along, around, major, minor) with one hole round the tube, split in two by a bridge
// (hole_closing.h, CloseBridgedHoles): the faces between rings 0 and 1 are cut out but for the
// two quads at angles 0 and 1, which keep the two sides of the cut joined; a band of two
// triangles then joins ring 0 between angles 2 and 3 to ring 1 between angles around - 1 and 0,
// over those two quads. That band splits the hole into two loops of around - 1 vertices, each
// winding once round the tube, and its two triangles share the one edge between the loops:
// (ring 0, angle 3) - (ring 1, angle around - 1). around >= 6.
TriangleMesh TorusWithBridgedHoles(int along, int around, double major, double minor);

// Sizes of the boundary loops of `mesh` over its live half-edges, sorted ascending.
std::vector<size_t> BoundaryLoopSizes(const Mesh& mesh);

// Converts and aborts the test on failure.
Mesh MustToMesh(const TriangleMesh& triangles);

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_SHAPES_H_
