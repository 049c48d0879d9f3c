#include "clients/remote/proto_json.h"

#include <cstdint>
#include <string_view>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/util/json_util.h>
#include "absl/strings/numbers.h"

namespace surfmap::cli {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using nlohmann::json;

void NumbersIn(const Descriptor& type, json& object);

// A 64-bit integer printed as a string becomes a number; anything else
// (already a number, or not an integer) is left as protobuf wrote it.
void IntegerToNumber(const FieldDescriptor& field, json& value) {
  if (!value.is_string()) return;
  const std::string& text = value.get_ref<const std::string&>();
  if (field.cpp_type() == FieldDescriptor::CPPTYPE_INT64) {
    int64_t n = 0;
    if (absl::SimpleAtoi(text, &n)) value = n;
  } else {
    uint64_t n = 0;
    if (absl::SimpleAtoi(text, &n)) value = n;
  }
}

// Well-known types (Timestamp, Duration, wrappers, Struct) have their own JSON
// forms, which are kept.
bool IsWellKnown(const Descriptor& type) {
  return std::string_view(type.full_name()).substr(0, 16) == "google.protobuf.";
}

void ConvertValue(const FieldDescriptor& field, json& value) {
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT64:
    case FieldDescriptor::CPPTYPE_UINT64:
      IntegerToNumber(field, value);
      break;
    case FieldDescriptor::CPPTYPE_MESSAGE:
      if (value.is_object() && !IsWellKnown(*field.message_type())) NumbersIn(*field.message_type(), value);
      break;
    default:
      break;
  }
}

void NumbersIn(const Descriptor& type, json& object) {
  for (int i = 0; i < type.field_count(); ++i) {
    const FieldDescriptor& field = *type.field(i);
    auto it = object.find(field.name());
    if (it == object.end()) continue;
    json& value = *it;
    if (field.is_map()) {
      // Keys stay strings (JSON object keys); values are converted.
      const FieldDescriptor& map_value = *field.message_type()->map_value();
      if (value.is_object()) {
        for (auto& [key, element] : value.items()) ConvertValue(map_value, element);
      }
    } else if (field.is_repeated()) {
      if (value.is_array()) {
        for (json& element : value) ConvertValue(field, element);
      }
    } else {
      ConvertValue(field, value);
    }
  }
}

}  // namespace

json ProtoToJson(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string text;
  if (!google::protobuf::util::MessageToJsonString(message, &text, options).ok()) return json::object();
  json parsed = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!parsed.is_object()) return json::object();
  NumbersIn(*message.GetDescriptor(), parsed);
  return parsed;
}

}  // namespace surfmap::cli
