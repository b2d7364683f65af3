#include "server/client_certificate_identity.h"

#include <grpc/grpc_security_constants.h>

#include <string>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace neuralmesh::server {

absl::StatusOr<ClientRoles> ParseClientRoles(absl::string_view text) {
  ClientRoles roles;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || line.front() == '#') continue;
    const auto bad_line = [line_number](absl::string_view why) {
      return absl::InvalidArgumentError(absl::StrCat("line ", line_number, ": ", why));
    };
    const size_t last_space = line.find_last_of(" \t");
    if (last_space == absl::string_view::npos) {
      return bad_line("expected COMMON_NAME ROLE (admin, user or reader)");
    }
    const std::string name(absl::StripAsciiWhitespace(line.substr(0, last_space)));
    absl::StatusOr<AccessRole> role = ParseAccessRole(line.substr(last_space + 1));
    if (!role.ok()) return bad_line(role.status().message());
    if (!roles.emplace(name, *role).second) {
      return bad_line(absl::StrCat("the common name \"", name, "\" is listed twice"));
    }
  }
  if (roles.empty()) {
    return absl::InvalidArgumentError(
        "no client in it (one per line: COMMON_NAME ROLE; '#' starts a comment line)");
  }
  return roles;
}

void ClientCertificateIdentity::ReplaceRoles(ClientRoles roles) {
  absl::MutexLock lock(&mu_);
  roles_ = std::move(roles);
}

std::optional<AccessRole> ClientCertificateIdentity::RoleOf(
    absl::string_view common_name) const {
  absl::MutexLock lock(&mu_);
  if (auto it = roles_.find(common_name); it != roles_.end()) return it->second;
  return others_;
}

grpc::Status ClientCertificateIdentity::Process(const InputMetadata& /*auth_metadata*/,
                                                grpc::AuthContext* context,
                                                OutputMetadata* /*consumed_auth_metadata*/,
                                                OutputMetadata* /*response_metadata*/) {
  const std::vector<grpc::string_ref> names =
      context->FindPropertyValues(GRPC_X509_CN_PROPERTY_NAME);
  if (names.empty() || names.front().empty()) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "the client certificate has no common name to name its client by");
  }
  const absl::string_view name(names.front().data(), names.front().size());
  const std::optional<AccessRole> role = RoleOf(name);
  if (!role.has_value()) {
    return grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                        absl::StrCat("the client certificate's common name \"", name,
                                     "\" has no role on this server (--client_roles_file)"));
  }
  context->AddProperty(kClientProperty, names.front());
  context->AddProperty(kRoleProperty, std::string(AccessRoleName(*role)));
  return grpc::Status::OK;
}

}  // namespace neuralmesh::server
