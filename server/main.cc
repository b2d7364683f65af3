// neuralmesh-server: serves neuralmesh.v1.ReconstructionService (with grpc.health.v1 and
// server reflection) until SIGTERM or SIGINT, then shuts down gracefully: every open stream
// ends with UNAVAILABLE and the process exits.
#include <pthread.h>
#include <signal.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include <grpcpp/grpcpp.h>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "core/io/file_contents.h"
#include "core/status_macros.h"
#include "core/version.h"
#include "http/bearer_token.h"
#include "server/access_tokens.h"
#include "server/server.h"

ABSL_FLAG(std::string, host, "127.0.0.1",
          "Address to listen on; 0.0.0.0 for every IPv4 interface, [::] for every interface.");
ABSL_FLAG(int, port, 50051, "Port to listen on; 0 picks a free one (printed at start).");
ABSL_FLAG(int, worker_threads, 0,
          "Learning threads shared by all sessions in time slices; 0: one per core.");
ABSL_FLAG(int, encoder_threads, 1, "Threads that Draco-encode the published meshes.");
ABSL_FLAG(int, filter_threads, 1,
          "Threads that ingest the batches of sessions with outlier_removal (the filter takes "
          "about 5-11 us per point), so that gRPC's own threads never wait on it.");
ABSL_FLAG(absl::Duration, time_slice, absl::Milliseconds(20),
          "Learning time a session gets per turn on a worker thread.");
ABSL_FLAG(int, max_sessions, 64, "Sessions held at once, in any state.");
ABSL_FLAG(int, max_sessions_per_client, 0,
          "Of --max_sessions, the most one client of --access_tokens_file may hold (a named "
          "token's CLIENT; sessions of unnamed tokens count against --max_sessions only); 0: no "
          "limit of its own.");
ABSL_FLAG(int64_t, max_points_per_session, int64_t{1} << 26,
          "Points one session accepts in total.");
ABSL_FLAG(int64_t, max_batch_points,
          static_cast<int64_t>(neuralmesh::server::SessionLimits().max_batch_points),
          "Points one batch may hold. A packed batch takes 12 bytes a point, 31 with weights, "
          "normals and colours, and must also fit --max_message_bytes.");
ABSL_FLAG(int, max_message_bytes, 64 << 20,
          "Largest gRPC message accepted or sent, in bytes.");
ABSL_FLAG(absl::Duration, idle_timeout, absl::Minutes(30),
          "Delete sessions that had no open stream and no activity (calls, learning) for this "
          "long; 'inf' never does.");
ABSL_FLAG(std::string, tls_cert_file, "",
          "PEM file with the server's TLS certificate (then any intermediates); set: the port "
          "speaks TLS only. Needs --tls_key_file. SIGHUP reads it, the key and the client CAs "
          "again: a renewed certificate applies to new connections within a second, without a "
          "restart.");
ABSL_FLAG(std::string, tls_key_file, "", "PEM file with the private key of --tls_cert_file.");
ABSL_FLAG(std::string, tls_client_ca_file, "",
          "PEM file with the CAs that sign client certificates; set: mutual TLS, every client "
          "must present a certificate signed by one of them. Needs --tls_cert_file.");
ABSL_FLAG(std::string, client_certificate_role, "",
          "With --tls_client_ca_file and without --access_tokens_file: admin, user or reader. "
          "The common name of a client's certificate names its client, which has this role "
          "(as a named token's, see --access_tokens_file): with user, each client sees and "
          "changes only the sessions it created. With --client_roles_file, the role of the "
          "common names it does not list. Empty: every client may do everything (with "
          "--client_roles_file: only those it lists may call).");
ABSL_FLAG(std::string, client_roles_file, "",
          "With --tls_client_ca_file and without --access_tokens_file: a file of client roles, "
          "one per line as 'COMMON_NAME ROLE' (the role last: admin, user or reader, as for "
          "--access_tokens_file; '#' starts a comment line). A client whose certificate's common "
          "name is listed has that role; others get --client_certificate_role, or are refused "
          "(PERMISSION_DENIED). SIGHUP reads the file again (calls already running go on).");
ABSL_FLAG(std::string, access_tokens_file, "",
          "File of access tokens, one per line as 'TOKEN [CLIENT [ROLE]]' ('#' starts a "
          "comment line; a token has at least 16 printable characters); set: every call except "
          "health checks must carry 'authorization: Bearer TOKEN' with one of them. ROLE is "
          "user (the default for a named token: it creates sessions and sees and changes only "
          "those CLIENT created), reader (it lists, gets and watches every session and changes "
          "none) or admin (every session; a token alone is one). Needs --tls_cert_file. SIGHUP "
          "reads the file again (calls already running go on).");
ABSL_FLAG(std::string, state_dir, "",
          "Directory in which every session is kept (its settings, state, points, latest "
          "mesh and the learner's mesh at its latest milestone or checkpoint_interval) and from "
          "which a server started again restores them while it answers (calls on a session "
          "get UNAVAILABLE until it is back): uploads and watches go on where they "
          "were, and sessions that were learning learn on from that mesh. "
          "One server at a time uses a directory. Empty: sessions live in memory and a "
          "restart loses them.");
ABSL_FLAG(bool, state_sync, true,
          "With --state_dir: a batch or a finish or cancel is acknowledged only once it is on "
          "the disk (fdatasync). false: once the kernel has it, which survives a crash of the "
          "server but perhaps not one of the machine.");
ABSL_FLAG(absl::Duration, checkpoint_interval, neuralmesh::server::kDefaultCheckpointInterval,
          "With --state_dir: besides the learner's mesh at every milestone, keep a refresh of a "
          "learning session as its checkpoint when this long has passed since the last one, so "
          "that a restart costs at most about this much learning. 0: milestones only.");
ABSL_FLAG(bool, log_sessions, true,
          "Print a line on standard output when a session is created, finishes, is cancelled, "
          "fails or is deleted (with the time, the client's address and the figures).");
ABSL_FLAG(std::string, log_calls, "none",
          "With --log_sessions, also print a line for gRPC calls: none, errors (every call that "
          "ends with a status other than OK) or all; each with the method, the client's address "
          "and token name, the status and message, and how long the call took.");
ABSL_FLAG(int, metrics_port, -1,
          "Port of the metrics page, on plain HTTP (or HTTPS: --metrics_tls): /metrics (the "
          "Prometheus text format: "
          "sessions by state, points, Basic Steps, meshes published, gRPC calls by method and "
          "status; totals only, no session ids or names) and /healthz (200 while serving, 503 "
          "while shutting down). 0 picks a free one (printed at start); -1: none.");
ABSL_FLAG(std::string, metrics_host, "",
          "Address the metrics page listens on; empty: --host's.");
ABSL_FLAG(bool, metrics_tls, false,
          "Serve the metrics page over HTTPS with the certificate and key of --tls_cert_file "
          "and --tls_key_file (SIGHUP renews it with them); a client certificate is asked for "
          "only with --metrics_client_certificate. Needs --metrics_port and --tls_cert_file.");
ABSL_FLAG(bool, metrics_client_certificate, false,
          "With --metrics_tls and --tls_client_ca_file: /metrics answers only clients that "
          "present a certificate the client CAs signed (403 otherwise; Prometheus: "
          "tls_config.cert_file and key_file), and with --client_roles_file or "
          "--client_certificate_role only those whose certificate's common name has a role; "
          "/healthz stays open to probes without one. SIGHUP reads the CAs again with the "
          "certificate, and the roles.");
ABSL_FLAG(std::string, metrics_token_file, "",
          "File holding a token (16 or more letters, digits or -._~) that /metrics asks for "
          "as 'Authorization: Bearer TOKEN' (401 otherwise; Prometheus: authorization."
          "credentials_file); /healthz stays open to probes. SIGHUP reads it again. Needs "
          "--metrics_port; use it with --metrics_tls, or the token crosses the network in the "
          "clear.");
ABSL_FLAG(absl::Duration, shutdown_grace, absl::Seconds(5),
          "On SIGTERM/SIGINT, how long calls may take to end before they are cancelled.");

namespace {

// The tokens of --access_tokens_file, which is set.
absl::StatusOr<std::vector<neuralmesh::server::AccessToken>> AccessTokensFromFlag() {
  NM_ASSIGN_OR_RETURN(const std::string text,
                      neuralmesh::ReadFileNamedByFlag("access_tokens_file",
                                                      absl::GetFlag(FLAGS_access_tokens_file)));
  absl::StatusOr<std::vector<neuralmesh::server::AccessToken>> tokens =
      neuralmesh::server::ParseAccessTokens(text);
  if (!tokens.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--access_tokens_file: ", tokens.status().message()));
  }
  return tokens;
}

// The roles of --client_roles_file, which is set.
absl::StatusOr<neuralmesh::server::ClientRoles> ClientRolesFromFlag() {
  NM_ASSIGN_OR_RETURN(
      const std::string text,
      neuralmesh::ReadFileNamedByFlag("client_roles_file", absl::GetFlag(FLAGS_client_roles_file)));
  absl::StatusOr<neuralmesh::server::ClientRoles> roles =
      neuralmesh::server::ParseClientRoles(text);
  if (!roles.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--client_roles_file: ", roles.status().message()));
  }
  return roles;
}

// The TLS identity of --tls_cert_file, --tls_key_file and --tls_client_ca_file.
absl::StatusOr<neuralmesh::server::ServerTls> TlsFromFlags() {
  neuralmesh::server::ServerTls tls;
  struct PemFlag {
    const char* flag;
    std::string path;
    std::string* contents;
  };
  const PemFlag pem_flags[] = {
      {"tls_cert_file", absl::GetFlag(FLAGS_tls_cert_file), &tls.certificate_chain},
      {"tls_key_file", absl::GetFlag(FLAGS_tls_key_file), &tls.private_key},
      {"tls_client_ca_file", absl::GetFlag(FLAGS_tls_client_ca_file), &tls.client_ca_certificates}};
  for (const PemFlag& pem : pem_flags) {
    NM_ASSIGN_OR_RETURN(*pem.contents, neuralmesh::ReadFileNamedByFlag(pem.flag, pem.path));
  }
  return tls;
}

absl::StatusOr<neuralmesh::server::ServerSecurity> SecurityFromFlags() {
  neuralmesh::server::ServerSecurity security;
  NM_ASSIGN_OR_RETURN(security.tls, TlsFromFlags());
  if (!absl::GetFlag(FLAGS_access_tokens_file).empty()) {
    NM_ASSIGN_OR_RETURN(security.access_tokens, AccessTokensFromFlag());
  }
  if (!absl::GetFlag(FLAGS_client_roles_file).empty()) {
    NM_ASSIGN_OR_RETURN(security.client_roles, ClientRolesFromFlag());
  }
  if (const std::string role = absl::GetFlag(FLAGS_client_certificate_role); !role.empty()) {
    absl::StatusOr<neuralmesh::server::AccessRole> parsed =
        neuralmesh::server::ParseAccessRole(role);
    if (!parsed.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("--client_certificate_role: ", parsed.status().message()));
    }
    security.client_certificate_role = *parsed;
  }
  return security;
}

// The token of --metrics_token_file ("" without the flag).
absl::StatusOr<std::string> MetricsTokenFromFlag() {
  const std::string path = absl::GetFlag(FLAGS_metrics_token_file);
  if (path.empty()) return std::string();
  NM_ASSIGN_OR_RETURN(const std::string contents,
                      neuralmesh::ReadFileNamedByFlag("metrics_token_file", path));
  absl::StatusOr<std::string> token = neuralmesh::http::ParseSecret(contents, "the metrics token");
  if (!token.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics_token_file: ", token.status().message()));
  }
  return token;
}

// On SIGHUP: the files of --tls_cert_file, --tls_key_file and --tls_client_ca_file, of
// --access_tokens_file, of --client_roles_file and of --metrics_token_file replace what the
// server has; what is now wrong leaves the old in place, and the reason is printed.
void ReloadSecurity(neuralmesh::server::ReconstructionServer& server) {
  const bool tls = !absl::GetFlag(FLAGS_tls_cert_file).empty();
  const bool tokens_file = !absl::GetFlag(FLAGS_access_tokens_file).empty();
  const bool roles_file = !absl::GetFlag(FLAGS_client_roles_file).empty();
  const bool metrics_token_file = !absl::GetFlag(FLAGS_metrics_token_file).empty();
  if (!tls && !tokens_file && !metrics_token_file) {
    std::printf("neuralmesh-server: SIGHUP received; no TLS, access tokens or metrics token "
                "files to read again\n");
  }
  if (tls) {
    absl::StatusOr<neuralmesh::server::ServerTls> identity = TlsFromFlags();
    const absl::Status replaced = identity.ok() ? server.ReplaceTls(*identity) : identity.status();
    if (replaced.ok()) {
      std::printf("neuralmesh-server: SIGHUP received; TLS certificate and key read again (new "
                  "connections within a second)\n");
    } else {
      std::fprintf(stderr,
                   "neuralmesh-server: SIGHUP received; the old TLS certificate stays: %s\n",
                   std::string(replaced.message()).c_str());
    }
  }
  if (tokens_file) {
    absl::StatusOr<std::vector<neuralmesh::server::AccessToken>> tokens = AccessTokensFromFlag();
    const absl::Status replaced =
        tokens.ok() ? server.ReplaceAccessTokens(*tokens) : tokens.status();
    if (replaced.ok()) {
      std::printf("neuralmesh-server: SIGHUP received; %zu access tokens read again\n",
                  tokens->size());
    } else {
      std::fprintf(stderr,
                   "neuralmesh-server: SIGHUP received; the old access tokens stay: %s\n",
                   std::string(replaced.message()).c_str());
    }
  }
  if (roles_file) {
    absl::StatusOr<neuralmesh::server::ClientRoles> roles = ClientRolesFromFlag();
    const size_t count = roles.ok() ? roles->size() : 0;
    const absl::Status replaced =
        roles.ok() ? server.ReplaceClientRoles(*std::move(roles)) : roles.status();
    if (replaced.ok()) {
      std::printf("neuralmesh-server: SIGHUP received; %zu client roles read again\n", count);
    } else {
      std::fprintf(stderr, "neuralmesh-server: SIGHUP received; the old client roles stay: %s\n",
                   std::string(replaced.message()).c_str());
    }
  }
  if (metrics_token_file) {
    absl::StatusOr<std::string> token = MetricsTokenFromFlag();
    const absl::Status replaced =
        token.ok() ? server.ReplaceMetricsToken(*token) : token.status();
    if (replaced.ok()) {
      std::printf("neuralmesh-server: SIGHUP received; metrics token read again\n");
    } else {
      std::fprintf(stderr, "neuralmesh-server: SIGHUP received; the old metrics token stays: %s\n",
                   std::string(replaced.message()).c_str());
    }
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  // --help lists the flags of this file (absl's default looks for a file named after the
  // program, which has none).
  absl::FlagsUsageConfig usage;
  usage.contains_help_flags = [](absl::string_view file) {
    return absl::EndsWith(file, "server/main.cc");
  };
  usage.contains_helpshort_flags = usage.contains_help_flags;
  usage.version_string = [] {
    return neuralmesh::VersionLine("neuralmesh-server", absl::StrCat("gRPC ", grpc::Version())) +
           "\n";
  };
  absl::SetFlagsUsageConfig(usage);
  absl::SetProgramUsageMessage(
      "Serves Neural Meshes surface reconstruction over gRPC (neuralmesh.v1).\n"
      "Usage: neuralmesh-server [--host=127.0.0.1] [--port=50051] [flags]");
  absl::ParseCommandLine(argc, argv);

  // Block the shutdown signals and SIGHUP in every thread (gRPC's and ours inherit this mask)
  // and take them synchronously on one thread below.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  // A write past a file size limit (ulimit -f) then fails with EFBIG, which refuses the batch
  // that --state_dir could not store, instead of killing the server.
  signal(SIGXFSZ, SIG_IGN);

  neuralmesh::server::ServerOptions options;
  options.address =
      absl::StrCat(absl::GetFlag(FLAGS_host), ":", absl::GetFlag(FLAGS_port));
  const int workers = absl::GetFlag(FLAGS_worker_threads);
  options.worker_threads =
      workers > 0 ? workers : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  options.encoder_threads = absl::GetFlag(FLAGS_encoder_threads);
  options.filter_threads = absl::GetFlag(FLAGS_filter_threads);
  options.time_slice = absl::GetFlag(FLAGS_time_slice);
  options.max_message_bytes = absl::GetFlag(FLAGS_max_message_bytes);
  const int max_sessions = absl::GetFlag(FLAGS_max_sessions);
  const int max_per_client = absl::GetFlag(FLAGS_max_sessions_per_client);
  const int64_t max_points = absl::GetFlag(FLAGS_max_points_per_session);
  const int64_t max_batch = absl::GetFlag(FLAGS_max_batch_points);
  if (max_sessions < 1 || max_points < 4 || max_batch < 1 || max_per_client < 0) {
    std::fprintf(stderr,
                 "neuralmesh-server: --max_sessions and --max_batch_points must be at least 1, "
                 "--max_points_per_session at least 4, --max_sessions_per_client at least 0\n");
    return 2;
  }
  options.limits.max_sessions = static_cast<size_t>(max_sessions);
  options.limits.max_sessions_per_client = static_cast<size_t>(max_per_client);
  options.limits.max_points_per_session = static_cast<size_t>(max_points);
  options.limits.max_batch_points = static_cast<size_t>(max_batch);
  options.limits.idle_timeout = absl::GetFlag(FLAGS_idle_timeout);
  options.state_dir = absl::GetFlag(FLAGS_state_dir);
  options.state_sync = absl::GetFlag(FLAGS_state_sync);
  options.checkpoint_interval = absl::GetFlag(FLAGS_checkpoint_interval);
  options.metrics_port = absl::GetFlag(FLAGS_metrics_port);
  options.metrics_host = absl::GetFlag(FLAGS_metrics_host);
  options.metrics_tls = absl::GetFlag(FLAGS_metrics_tls);
  options.metrics_client_certificate = absl::GetFlag(FLAGS_metrics_client_certificate);
  if (options.checkpoint_interval < absl::ZeroDuration() ||
      options.checkpoint_interval == absl::InfiniteDuration()) {
    std::fprintf(stderr,
                 "neuralmesh-server: --checkpoint_interval must be a finite duration >= 0 (e.g. "
                 "30s, 5m), not %s\n",
                 absl::FormatDuration(options.checkpoint_interval).c_str());
    return 2;
  }
  if (absl::GetFlag(FLAGS_log_sessions)) {
    options.event_sink = neuralmesh::server::EventLog::StandardOutput();
  }
  absl::StatusOr<neuralmesh::server::CallLogLevel> log_calls =
      neuralmesh::server::ParseCallLogLevel(absl::GetFlag(FLAGS_log_calls));
  if (!log_calls.ok()) {
    std::fprintf(stderr, "neuralmesh-server: --log_calls: %s\n",
                 std::string(log_calls.status().message()).c_str());
    return 2;
  }
  options.log_calls = *log_calls;
  absl::StatusOr<neuralmesh::server::ServerSecurity> security = SecurityFromFlags();
  if (!security.ok()) {
    std::fprintf(stderr, "neuralmesh-server: %s\n", security.status().ToString().c_str());
    return 2;
  }
  options.security = *std::move(security);
  absl::StatusOr<std::string> metrics_token = MetricsTokenFromFlag();
  if (!metrics_token.ok()) {
    std::fprintf(stderr, "neuralmesh-server: %s\n", metrics_token.status().ToString().c_str());
    return 2;
  }
  options.metrics_token = *std::move(metrics_token);
  // PackedPoints: 12 bytes a point for the position, 4 for a weight, 12 for a normal, 3 for a
  // colour.
  constexpr int64_t kLargestPackedPointBytes = 31;
  if (max_batch > options.max_message_bytes / kLargestPackedPointBytes) {
    std::fprintf(stderr,
                 "neuralmesh-server: warning: a packed batch of --max_batch_points=%lld points "
                 "with weights, normals and colours takes about %.0f bytes, more than "
                 "--max_message_bytes=%d; gRPC refuses such messages before the server sees "
                 "them\n",
                 static_cast<long long>(max_batch),
                 static_cast<double>(max_batch) * kLargestPackedPointBytes,
                 options.max_message_bytes);
  }

  absl::StatusOr<std::unique_ptr<neuralmesh::server::ReconstructionServer>> server =
      neuralmesh::server::ReconstructionServer::Start(options);
  if (!server.ok()) {
    std::fprintf(stderr, "neuralmesh-server: %s\n", server.status().ToString().c_str());
    return 1;
  }
  const neuralmesh::server::ServerSecurity& secured = options.security;
  std::string clients;
  if (!secured.access_tokens.empty()) {
    clients = absl::StrCat(", ", secured.access_tokens.size(), " access tokens");
  } else if (secured.names_clients_by_certificate()) {
    clients = ", clients named by their certificates";
    if (!secured.client_roles.empty()) {
      absl::StrAppend(&clients, ", ", secured.client_roles.size(), " with roles of their own");
    }
    if (secured.client_certificate_role.has_value()) {
      absl::StrAppend(&clients, secured.client_roles.empty() ? " as " : ", others as ",
                      neuralmesh::server::AccessRoleName(*secured.client_certificate_role), "s");
    } else {
      absl::StrAppend(&clients, ", others refused");
    }
  }
  std::printf("neuralmesh-server listening on %s:%d (%d worker threads; %s%s)\n",
              absl::GetFlag(FLAGS_host).c_str(), (*server)->port(), options.worker_threads,
              !secured.tls.enabled()                       ? "plaintext"
              : secured.tls.client_ca_certificates.empty() ? "TLS"
                                                           : "mutual TLS",
              clients.c_str());
  if (const std::string url = (*server)->metrics_url(); !url.empty()) {
    std::printf("neuralmesh-server: metrics on %s%s\n", url.c_str(),
                options.metrics_token.empty() ? "" : " (with the token of --metrics_token_file)");
    if (!options.metrics_token.empty() && !options.metrics_tls) {
      std::fprintf(stderr,
                   "neuralmesh-server: warning: the metrics token crosses the network in the "
                   "clear; --metrics_tls serves the page over HTTPS\n");
    }
  }
  std::fflush(stdout);
  // The stored sessions are restored while the server answers; the report comes when it is done.
  std::thread restore_reporter;
  if (!options.state_dir.empty()) {
    restore_reporter = std::thread([&server, &options] {
      const neuralmesh::server::RestoreReport restored = (*server)->WaitForRestore();
      for (const std::string& problem : restored.problems) {
        std::fprintf(stderr, "neuralmesh-server: --state_dir: %s\n", problem.c_str());
      }
      std::printf("neuralmesh-server: %zu sessions (%zu points) restored from %s in %.2f s\n",
                  restored.sessions, restored.points, options.state_dir.c_str(),
                  absl::ToDoubleSeconds(restored.took));
      std::fflush(stdout);
    });
  }

  int signal_number = 0;
  while (sigwait(&signals, &signal_number) == 0 && signal_number == SIGHUP) {
    ReloadSecurity(**server);
    std::fflush(stdout);
  }
  std::printf("neuralmesh-server: %s received, shutting down\n",
              signal_number == SIGTERM ? "SIGTERM" : "SIGINT");
  std::fflush(stdout);
  (*server)->Shutdown(absl::GetFlag(FLAGS_shutdown_grace));
  if (restore_reporter.joinable()) restore_reporter.join();  // Shutdown ends the restore.
  server->reset();
  std::printf("neuralmesh-server: stopped\n");
  return 0;
}
