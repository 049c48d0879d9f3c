#include "server/service/server_runner.h"

#include <csignal>
#include <cstdio>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/security/server_credentials.h>
#include <spdlog/spdlog.h>
#include <google/protobuf/descriptor.h>
#include "absl/strings/str_cat.h"
#include "server/base/mutex.h"
#include "server/base/task_queue.h"
#include "server/base/timer_queue.h"
#include "server/base/worker_pool.h"
#include "server/jobs/job_coordinator.h"
#include "server/service/grpc_services.h"
#include "server/service/startup_checks.h"
#include "server/service/status_interceptor.h"
#include "server/service/reflection_v1_service.h"
#include "server/service/watch_update_cache.h"
#include "storage/sqlite_store.h"

namespace surfmap {
namespace {

absl::Status WritePortFile(const std::string& path, int port) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << port << "\n";
    if (!out) return absl::UnavailableError(absl::StrCat("cannot write port file ", tmp));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    return absl::UnavailableError(absl::StrCat("cannot rename ", tmp, " to ", path));
  }
  return absl::OkStatus();
}

// Plaintext, or TLS from the config's PEM files (with client certificates
// required and verified when a client CA is set).
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> ListenCredentials(const ServerConfig& config) {
  if (!config.tls()) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions options;
  grpc::SslServerCredentialsOptions::PemKeyCertPair pair;
  absl::StatusOr<std::string> cert = ReadPemFile("tls_cert_file", config.tls_cert_file);
  if (!cert.ok()) return cert.status();
  absl::StatusOr<std::string> key = ReadPemFile("tls_key_file", config.tls_key_file);
  if (!key.ok()) return key.status();
  pair.cert_chain = *cert;
  pair.private_key = *key;
  options.pem_key_cert_pairs.push_back(pair);
  if (!config.tls_client_ca_file.empty()) {
    absl::StatusOr<std::string> ca = ReadPemFile("tls_client_ca_file", config.tls_client_ca_file);
    if (!ca.ok()) return ca.status();
    options.pem_root_certs = *ca;
    options.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  return grpc::SslServerCredentials(options);
}

// Full names of every method this server answers (for the status interceptor).
std::set<std::string> ServedMethods() {
  std::set<std::string> methods;
  const google::protobuf::DescriptorPool* pool = google::protobuf::DescriptorPool::generated_pool();
  for (const char* service : {"surfmap.v1.ObjectService", "surfmap.v1.JobService", "surfmap.v1.ProbeService",
                              "surfmap.v1.MapService", "surfmap.v1.TraceService"}) {
    const google::protobuf::ServiceDescriptor* d = pool->FindServiceByName(service);
    if (d == nullptr) continue;
    for (int i = 0; i < d->method_count(); ++i) methods.insert(absl::StrCat("/", service, "/", d->method(i)->name()));
  }
  methods.insert({"/grpc.health.v1.Health/Check", "/grpc.health.v1.Health/Watch",
                  "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo",
                  "/grpc.reflection.v1.ServerReflection/ServerReflectionInfo"});
  return methods;
}

}  // namespace

absl::Status RunServer(const ServerConfig& config, const std::string& port_file) {
  // Signals are handled by sigwait below: block them before any thread starts
  // so every thread inherits the mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  // Declared before the store and the coordinator, destroyed after them: a
  // store callback always finds the queue it posts to.
  TaskQueue completions;
  TimerQueue timers;
  WorkerPool probe_pool(config.probe_threads, /*max_queued=*/4096);
  WorkerPool pool(config.worker_threads, /*max_queued=*/4096);
  if (absl::Status s = CheckDatabaseWritable(config.db_path); !s.ok()) return s;
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials = ListenCredentials(config);
  if (!credentials.ok()) return credentials.status();
  absl::StatusOr<std::unique_ptr<SqliteStore>> store = SqliteStore::Open(config.db_path);
  if (!store.ok()) return store.status();
  CoordinatorOptions options;
  options.default_lease_ms = static_cast<int64_t>(config.default_lease_s * 1000);
  JobCoordinator coordinator(store->get(), JobExecutors{&completions, &probe_pool, &pool}, options);
  if (absl::Status s = coordinator.LoadJobs(); !s.ok()) return s;
  RequestGate gate(config.tokens);
  WatchUpdateCache watch_updates(&coordinator);
  ServiceContext services{&coordinator, &gate, &config, &pool, &timers, &watch_updates};

  ObjectServiceImpl objects(services);
  JobServiceImpl jobs(services);
  ProbeServiceImpl probes(services);
  MapServiceImpl maps(services);
  TraceServiceImpl traces(services);

  // Our services, then the standard ones: what reflection lists and what
  // health reports per name.
  const std::vector<std::string> api_services = {
      pb::ObjectService::service_full_name(), pb::JobService::service_full_name(),
      pb::ProbeService::service_full_name(), pb::MapService::service_full_name(),
      pb::TraceService::service_full_name()};
  std::vector<std::string> listed = api_services;
  listed.insert(listed.end(), {"grpc.health.v1.Health", "grpc.reflection.v1.ServerReflection",
                               "grpc.reflection.v1alpha.ServerReflection"});
  ReflectionV1Service reflection_v1(listed);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();  // v1alpha (Debian's library)
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(config.listen, *credentials, &port);
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> interceptors;
  interceptors.push_back(MakeStatusInterceptorFactory(ServedMethods()));
  builder.experimental().SetInterceptorCreators(std::move(interceptors));
  builder.SetMaxReceiveMessageSize(config.max_message_bytes);
  builder.SetMaxSendMessageSize(config.max_message_bytes);
  builder.RegisterService(&objects);
  builder.RegisterService(&jobs);
  builder.RegisterService(&probes);
  builder.RegisterService(&maps);
  builder.RegisterService(&traces);
  builder.RegisterService(&reflection_v1);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) return absl::UnavailableError(absl::StrCat("cannot listen on ", config.listen));
  // grpc.health.v1 per service as well as "" (the whole server, SERVING by
  // default): load balancers and Kubernetes probes ask by service name.
  grpc::HealthCheckServiceInterface* health = server->GetHealthCheckService();
  if (health != nullptr) {
    for (const std::string& name : api_services) health->SetServingStatus(name, true);
  }

  const std::string host = config.listen.substr(0, config.listen.rfind(':'));
  spdlog::info("surfmapd listening on {}:{} db={} auth={} transport={}", host, port, config.db_path,
               config.tokens.empty() ? "open" : "tokens",
               !config.tls() ? "plaintext" : config.tls_client_ca_file.empty() ? "tls" : "tls+client-certificates");
  if (!port_file.empty()) {
    if (absl::Status s = WritePortFile(port_file, port); !s.ok()) return s;
  }

  int signal_number = 0;
  sigwait(&signals, &signal_number);
  spdlog::info("surfmapd: signal {} received, shutting down (deadline {:.1f} s)", signal_number,
               config.shutdown_deadline_s);
  const auto deadline = std::chrono::system_clock::now() +
                        std::chrono::milliseconds(static_cast<int64_t>(config.shutdown_deadline_s * 1000));
  // NOT_SERVING for "" and every name while calls drain, so health checks
  // stop sending new work here first.
  if (health != nullptr) health->Shutdown();
  server->Shutdown(deadline);  // in-flight calls finish or are cancelled at the deadline
  server->Wait();
  // Every call has finished; work they started that outlives them (a job
  // being re-read, a watcher's last build) runs out in the order work flows:
  // pool -> store -> completions -> pool.
  pool.Drain();
  Notification synced;
  (*store)->SyncAsync([&synced](absl::Status) { synced.Notify(); });
  synced.WaitForNotification();
  completions.Drain();
  probe_pool.Drain();
  pool.Drain();
  spdlog::info("surfmapd: stopped");
  return absl::OkStatus();
}

}  // namespace surfmap
