// The neural mesh: OpenMesh's half-edge triangle mesh with double-precision points and the
// status attributes that collapses, removals and garbage collection need.
#ifndef NEURALMESH_CORE_MESH_H_
#define NEURALMESH_CORE_MESH_H_

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

namespace neuralmesh {

struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::PrevHalfedge);
};

// Every algorithm in core/ works on this type.
using Mesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;
using Vec3 = OpenMesh::Vec3d;
using Vec3f = OpenMesh::Vec3f;

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_MESH_H_
