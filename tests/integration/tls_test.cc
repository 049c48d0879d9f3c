// surfmapd over TLS, with certificates made at test time by the openssl
// command (a throw-away CA, a server certificate for 127.0.0.1 signed by it,
// a client certificate, and a second CA that signed nothing of the server's):
// a client trusting the CA connects; a plaintext client and a client trusting
// the wrong CA do not; the roles of the bearer tokens hold over TLS; a
// surfmap-rig process with --ca-file maps a job; with tls_client_ca_file a
// client without a certificate is refused. Refusals are logged at warn with
// the peer and the method, never the token.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <grpcpp/security/credentials.h>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "tests/support/child_process.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"
#include "tests/support/temp_dir.h"

#ifndef SURFMAP_RIG_PATH
#define SURFMAP_RIG_PATH "surfmap-rig"
#endif

namespace surfmap::itest {
namespace {

const char kRead[] = "tls-test-read-token-0001";
const char kProbe[] = "tls-test-probe-token-001";
const char kSteer[] = "tls-test-steer-token-001";

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The certificates of one test, in a temp dir.
class Pki {
 public:
  static absl::StatusOr<Pki> Make() {
    auto dir = TempDir::Create("surfmap-pki");
    if (!dir.ok()) return dir.status();
    Pki pki(std::move(*dir));
    if (absl::Status s = pki.Generate(); !s.ok()) return s;
    return pki;
  }
  std::string File(const std::string& name) const { return dir_.File(name); }
  std::string Pem(const std::string& name) const { return ReadText(File(name)); }

 private:
  explicit Pki(TempDir dir) : dir_(std::move(dir)) {}

  absl::Status Run(const std::string& command) {
    // The step's own redirections (printf > file) stay inside the subshell.
    const std::string line = absl::StrCat("cd '", dir_.path().string(), "' && (", command, ") >>openssl.log 2>&1");
    if (std::system(line.c_str()) != 0) {
      return absl::InternalError(absl::StrCat("openssl failed: ", command, "\n", ReadText(File("openssl.log"))));
    }
    return absl::OkStatus();
  }

  absl::Status Generate() {
    const char* steps[] = {
        // The CA and a second, unrelated one.
        "openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key -out ca.pem -days 2 -subj /CN=surfmap-test-ca",
        "openssl req -x509 -newkey rsa:2048 -nodes -keyout wrong.key -out wrong-ca.pem -days 2 "
        "-subj /CN=surfmap-wrong-ca",
        // The server: 127.0.0.1 and localhost, signed by the CA.
        "printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\nextendedKeyUsage=serverAuth\\n' > server.ext",
        "openssl req -newkey rsa:2048 -nodes -keyout server.key -out server.csr -subj /CN=localhost",
        "openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out server.pem -days 2 "
        "-extfile server.ext",
        // A client certificate signed by the CA.
        "printf 'extendedKeyUsage=clientAuth\\n' > client.ext",
        "openssl req -newkey rsa:2048 -nodes -keyout client.key -out client.csr -subj /CN=surfmap-test-rig",
        "openssl x509 -req -in client.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out client.pem -days 2 "
        "-extfile client.ext",
    };
    for (const char* step : steps) {
      if (absl::Status s = Run(step); !s.ok()) return s;
    }
    return absl::OkStatus();
  }

  TempDir dir_;
};

std::shared_ptr<grpc::ChannelCredentials> Trusting(const std::string& ca_pem, const std::string& key_pem = "",
                                                   const std::string& cert_pem = "") {
  grpc::SslCredentialsOptions options;
  options.pem_root_certs = ca_pem;
  options.pem_private_key = key_pem;
  options.pem_cert_chain = cert_pem;
  return grpc::SslCredentials(options);
}

std::string TlsConfig(const Pki& pki, bool client_certificates) {
  return absl::StrCat(R"({"tls_cert_file": ")", pki.File("server.pem"), R"(", "tls_key_file": ")",
                      pki.File("server.key"), "\"",
                      client_certificates ? absl::StrCat(R"(, "tls_client_ca_file": ")", pki.File("ca.pem"), "\"")
                                          : std::string(),
                      R"(, "tokens": {")", kRead, R"(": "read", ")", kProbe, R"(": "probe", ")", kSteer,
                      R"(": "steer"}})");
}

grpc::Status ListObjects(const std::shared_ptr<grpc::Channel>& channel, const std::string& token) {
  Stubs stubs(channel);
  pb::ListObjectsResponse out;
  return stubs.objects->ListObjects(Context(10, token).get(), pb::ListObjectsRequest(), &out);
}

TEST(TlsTest, OnlyAClientTrustingTheCaConnectsAndRolesHold) {
  ITEST_ASSERT_OK_AND_ASSIGN(pki, Pki::Make());
  ServerOptions options;
  options.config_json = TlsConfig(pki, /*client_certificates=*/false);
  options.channel_credentials = Trusting(pki.Pem("ca.pem"));
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start(options));
  EXPECT_NE(server->Log().find("transport=tls"), std::string::npos) << server->Log();

  // Trusting the CA: connected, and the token decides.
  GRPC_EXPECT_OK(ListObjects(server->channel(), kRead));
  // Plaintext to a TLS port, and TLS trusting another CA: no call goes through.
  const grpc::Status plaintext = ListObjects(MakeChannel(server->address(), true), kRead);
  EXPECT_EQ(plaintext.error_code(), grpc::StatusCode::UNAVAILABLE) << Describe(plaintext);
  const grpc::Status wrong_ca =
      ListObjects(MakeChannel(server->address(), true, Trusting(pki.Pem("wrong-ca.pem"))), kRead);
  EXPECT_EQ(wrong_ca.error_code(), grpc::StatusCode::UNAVAILABLE) << Describe(wrong_ca);

  // Roles over TLS: read < probe < steer.
  Stubs stubs(server->channel());
  EXPECT_EQ(ListObjects(server->channel(), "").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(ListObjects(server->channel(), "not-a-configured-token-0").error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  ITEST_ASSERT_OK_AND_ASSIGN(rig, MakeSceneRig("plate"));
  auto refused_upload = UploadSceneMesh(stubs, *rig, kRead);
  EXPECT_FALSE(refused_upload.ok());
  EXPECT_NE(std::string(refused_upload.status().message()).find("PERMISSION_DENIED"), std::string::npos)
      << refused_upload.status();
  ITEST_ASSERT_OK_AND_ASSIGN(object, UploadSceneMesh(stubs, *rig, kSteer));
  auto refused_job = CreateJob(stubs, UniformLevel0Spec(object.object_id(), 6), kProbe);
  EXPECT_FALSE(refused_job.ok());
  EXPECT_NE(std::string(refused_job.status().message()).find("PERMISSION_DENIED"), std::string::npos)
      << refused_job.status();
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(object.object_id(), 6), kSteer));
  {
    pb::LeaseCommandRequest lease;
    lease.set_rig_id("reader-as-rig");
    lease.set_job_id(job.job_id());
    pb::LeaseCommandResponse out;
    const grpc::Status status = stubs.probe->LeaseCommand(Context(10, kRead).get(), lease, &out);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << Describe(status);
  }

  // surfmap-rig --ca-file with the probe token measures the whole job over TLS.
  ITEST_ASSERT_OK_AND_ASSIGN(
      rig_process,
      ChildProcess::Start({SURFMAP_RIG_PATH, "--server", server->address(), "--ca-file", pki.File("ca.pem"), "--token",
                           kProbe, "--sim", "plate", "--job", absl::StrCat(job.job_id()), "--rig-id", "tls-rig",
                           "--spool", server->dir() + "/spool", "--quiet"},
                          server->dir() + "/rig.log"));
  ITEST_ASSERT_OK_AND_ASSIGN(exit_code, rig_process->Wait(std::chrono::seconds(120)));
  EXPECT_EQ(exit_code, 0) << rig_process->Output();
  {
    pb::GetJobRequest get;
    get.set_job_id(job.job_id());
    pb::GetJobResponse done;
    GRPC_ASSERT_OK(stubs.jobs->GetJob(Context(10, kRead).get(), get, &done));
    EXPECT_EQ(done.job().state(), pb::JOB_STATE_COMPLETED) << done.ShortDebugString();
  }
  // The rig without --ca-file (plaintext) gets nowhere.
  ITEST_ASSERT_OK_AND_ASSIGN(
      plaintext_rig,
      ChildProcess::Start({SURFMAP_RIG_PATH, "--server", server->address(), "--token", kProbe, "--sim", "plate",
                           "--job", absl::StrCat(job.job_id()), "--rig-id", "plaintext-rig", "--spool",
                           server->dir() + "/spool2", "--retry-for", "2", "--quiet"},
                          server->dir() + "/rig2.log"));
  ITEST_ASSERT_OK_AND_ASSIGN(plaintext_exit, plaintext_rig->Wait(std::chrono::seconds(60)));
  EXPECT_NE(plaintext_exit, 0) << plaintext_rig->Output();

  // Refusals: at warn, with the peer and the method, never the token.
  const std::string log = server->Log();
  EXPECT_NE(log.find("warning auth refused rpc=UploadObject peer=ipv4:127.0.0.1:"), std::string::npos) << log;
  EXPECT_NE(log.find("auth refused rpc=CreateJob"), std::string::npos) << log;
  EXPECT_NE(log.find("auth refused rpc=ListObjects"), std::string::npos) << log;
  for (const char* token : {kRead, kProbe, kSteer, "not-a-configured-token-0"}) {
    EXPECT_EQ(log.find(token), std::string::npos) << "the log shows a token";
  }
}

TEST(TlsTest, WithAClientCaEveryClientMustPresentACertificateSignedByIt) {
  ITEST_ASSERT_OK_AND_ASSIGN(pki, Pki::Make());
  ServerOptions options;
  options.config_json = TlsConfig(pki, /*client_certificates=*/true);
  options.channel_credentials = Trusting(pki.Pem("ca.pem"), pki.Pem("client.key"), pki.Pem("client.pem"));
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start(options));
  EXPECT_NE(server->Log().find("transport=tls+client-certificates"), std::string::npos) << server->Log();

  GRPC_EXPECT_OK(ListObjects(server->channel(), kRead));
  const grpc::Status no_certificate =
      ListObjects(MakeChannel(server->address(), true, Trusting(pki.Pem("ca.pem"))), kRead);
  EXPECT_EQ(no_certificate.error_code(), grpc::StatusCode::UNAVAILABLE) << Describe(no_certificate);
  // A certificate the client CA did not sign (the wrong CA's own).
  const grpc::Status foreign_certificate = ListObjects(
      MakeChannel(server->address(), true, Trusting(pki.Pem("ca.pem"), pki.Pem("wrong.key"), pki.Pem("wrong-ca.pem"))),
      kRead);
  EXPECT_EQ(foreign_certificate.error_code(), grpc::StatusCode::UNAVAILABLE) << Describe(foreign_certificate);
}

}  // namespace
}  // namespace surfmap::itest
