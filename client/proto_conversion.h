// Conversions from core's types to the neuralmesh.v1 messages that configure a session.
#ifndef NEURALMESH_CLIENT_PROTO_CONVERSION_H_
#define NEURALMESH_CLIENT_PROTO_CONVERSION_H_

#include "core/bounding_box.h"
#include "core/io/draco_codec.h"
#include "core/learning/learner_options.h"
#include "core/triangle_mesh.h"
#include "neuralmesh/v1/reconstruction.pb.h"

namespace neuralmesh::client {

// Every field set, so the server learns with exactly these parameters.
v1::LearnerOptions ToProto(const LearnerOptions& options);
// Quantization bits, encode speed (compression_speed) and decode speed.
v1::DracoOptions ToProto(const DracoOptions& options);
// A non-empty box.
v1::Box ToProto(const BoundingBox& box);
// A start mesh, packed exactly (CreateSessionRequest.start_mesh).
v1::StartMesh ToProto(const TriangleMesh& mesh);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_PROTO_CONVERSION_H_
