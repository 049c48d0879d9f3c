// Rig registrations: the service's stored records -> proto. The proto <->
// domain conversions both the server and the rig client use live in
// server/codec/rig_registration_proto.h.
#pragma once

#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/codec/rig_registration_proto.h"
#include "server/jobs/rig_registrations.h"

namespace surfmap {

namespace pb = ::surfmap::v1;

pb::RigRegistration RegisteredRigToProto(const RegisteredRig& rig);

}  // namespace surfmap
