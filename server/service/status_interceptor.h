// What gRPC answers by itself never reaches a client as UNIMPLEMENTED "".
// gRPC 1.51's callback server fails a call with UNIMPLEMENTED and no message
// when the request cannot be parsed (malformed bytes, or a string field that
// is not UTF-8) and when a handler throws before it returns a reactor; the
// client can then not tell a bug from a bad request from a missing method.
// This interceptor sees every call: a request that did not parse becomes
// INVALID_ARGUMENT naming the method and the message type's rules; an empty
// UNIMPLEMENTED from a method the server does have becomes INTERNAL; one
// from a method it does not have says so.
#pragma once

#include <memory>
#include <set>
#include <string>

#include <grpcpp/support/server_interceptor.h>

namespace surfmap {

// `methods`: the full names ("/surfmap.v1.ObjectService/UploadObject") of
// every method the server registered.
std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> MakeStatusInterceptorFactory(
    std::set<std::string> methods);

}  // namespace surfmap
