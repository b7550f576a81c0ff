// Checks of what deploy/ ships, without a cluster or a Docker engine (issue #11): every YAML
// parses; the kustomize base and overlays only name files that exist; the server Deployment has
// one GPU per pod, native gRPC probes on the health service (readiness on the overall status),
// the preStop drain, Prometheus annotations matching --metrics-port, the shared RWX snapshot
// volume mounted where --snapshot-dir points, config from the ConfigMap (every $(VAR) defined)
// and the admin key from a Secret; the ingress is gRPC with consistent hashing on x-rrg-session;
// compose reserves a GPU; the Dockerfile is multi-stage, non-root, with a HEALTHCHECK; the nginx
// template passes `nginx -t`; `docker compose config` runs when Docker Compose exists.
#include "tests/deploy/nginx_process.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

namespace rrg::test {
namespace {

namespace fs = std::filesystem;

const fs::path kDeploy = fs::path(RRG_SOURCE_DIR) / "deploy";

std::string read_text(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::vector<fs::path> yaml_files() {
  std::vector<fs::path> v;
  for (const auto& e : fs::recursive_directory_iterator(kDeploy))
    if (e.is_regular_file() && (e.path().extension() == ".yaml" || e.path().extension() == ".yml")) v.push_back(e.path());
  return v;
}

// The one document of `kind` (and `name`, when given) among the base's resources.
YAML::Node find_kind(const fs::path& dir, const std::string& kind, const std::string& name = "") {
  const YAML::Node k = YAML::LoadFile((dir / "kustomization.yaml").string());
  for (const auto& r : k["resources"]) {
    const fs::path p = dir / r.as<std::string>();
    if (!fs::is_regular_file(p)) continue;
    for (const auto& doc : YAML::LoadAllFromFile(p.string()))
      if (doc["kind"] && doc["kind"].as<std::string>() == kind &&
          (name.empty() || doc["metadata"]["name"].as<std::string>() == name))
        return doc;
  }
  return YAML::Node(YAML::NodeType::Undefined);  // false in a condition (a default Node is null, and true)
}

TEST(Manifests, EveryYamlParses) {
  const auto files = yaml_files();
  EXPECT_GE(files.size(), 10u);
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    std::vector<YAML::Node> docs;
    ASSERT_NO_THROW(docs = YAML::LoadAllFromFile(f.string()));
    EXPECT_FALSE(docs.empty());
    for (const auto& d : docs) EXPECT_TRUE(d.IsMap() || d.IsSequence());
  }
}

TEST(Manifests, KustomizeBaseAndOverlaysResolveToFilesThatExist) {
  const fs::path k8s = kDeploy / "k8s";
  std::vector<fs::path> dirs = {k8s / "base"};
  for (const auto& e : fs::directory_iterator(k8s / "overlays")) dirs.push_back(e.path());
  EXPECT_GE(dirs.size(), 3u) << "a base and at least two overlays";
  for (const auto& dir : dirs) {
    SCOPED_TRACE(dir.string());
    ASSERT_TRUE(fs::exists(dir / "kustomization.yaml"));
    const YAML::Node k = YAML::LoadFile((dir / "kustomization.yaml").string());
    EXPECT_EQ(k["kind"].as<std::string>(), "Kustomization");
    ASSERT_TRUE(k["resources"].IsSequence());
    for (const auto& r : k["resources"]) {
      const fs::path p = dir / r.as<std::string>();
      EXPECT_TRUE(fs::is_regular_file(p) || fs::exists(p / "kustomization.yaml")) << p;
    }
    for (const auto& p : k["patches"]) EXPECT_TRUE(fs::is_regular_file(dir / p["path"].as<std::string>())) << p["path"];
    // A strategic-merge patch must name an object of the base.
    for (const auto& p : k["patches"]) {
      if (p["target"]) continue;
      const YAML::Node patch = YAML::LoadFile((dir / p["path"].as<std::string>()).string());
      EXPECT_TRUE(find_kind(k8s / "base", patch["kind"].as<std::string>(), patch["metadata"]["name"].as<std::string>()))
          << p["path"] << " patches nothing in the base";
    }
    if (k["replicas"])
      for (const auto& r : k["replicas"]) EXPECT_TRUE(find_kind(k8s / "base", "Deployment", r["name"].as<std::string>()));
  }
}

TEST(Manifests, ServerPodHasOneGpuGrpcProbesDrainMetricsAndSharedSnapshots) {
  const fs::path base = kDeploy / "k8s/base";
  const YAML::Node dep = find_kind(base, "Deployment", "rrg-server");
  ASSERT_TRUE(dep) << "no Deployment rrg-server in the base";
  const YAML::Node pod = dep["spec"]["template"];
  const YAML::Node c = pod["spec"]["containers"][0];
  ASSERT_TRUE(c);
  // One GPU per pod.
  EXPECT_EQ(c["resources"]["limits"]["nvidia.com/gpu"].as<int>(), 1);
  EXPECT_EQ(c["resources"]["requests"]["nvidia.com/gpu"].as<int>(), 1);
  EXPECT_TRUE(c["resources"]["requests"]["cpu"] && c["resources"]["requests"]["memory"] && c["resources"]["limits"]["memory"]);
  // The arguments.
  std::map<std::string, std::string> flag;
  std::string args_text;
  for (const auto& a : c["args"]) {
    const std::string s = a.as<std::string>();
    args_text += s + " ";
    const auto eq = s.find('=');
    if (s.rfind("--", 0) == 0 && eq != std::string::npos) flag[s.substr(0, eq)] = s.substr(eq + 1);
  }
  EXPECT_EQ(c["args"][0].as<std::string>(), "serve");
  const std::string port = flag["--address"].substr(flag["--address"].rfind(':') + 1);
  EXPECT_EQ(port, "50051");
  // Native gRPC probes on the health service.
  for (const char* probe : {"livenessProbe", "readinessProbe", "startupProbe"}) {
    SCOPED_TRACE(probe);
    ASSERT_TRUE(c[probe]["grpc"]) << "not a gRPC probe";
    EXPECT_EQ(c[probe]["grpc"]["port"].as<std::string>(), port);
  }
  // Readiness on the overall status (SERVING until a drain), not on admission: a full server
  // must stay routable for its live sessions.
  EXPECT_TRUE(!c["readinessProbe"]["grpc"]["service"] || c["readinessProbe"]["grpc"]["service"].as<std::string>().empty());
  EXPECT_EQ(c["livenessProbe"]["grpc"]["service"].as<std::string>(), "liveness");
  // preStop drain.
  std::string pre_stop;
  for (const auto& a : c["lifecycle"]["preStop"]["exec"]["command"]) pre_stop += a.as<std::string>() + " ";
  EXPECT_NE(pre_stop.find("rrg drain"), std::string::npos) << pre_stop;
  EXPECT_GE(pod["spec"]["terminationGracePeriodSeconds"].as<int>(), 60);
  // Prometheus annotations match the metrics port.
  const YAML::Node ann = pod["metadata"]["annotations"];
  EXPECT_EQ(ann["prometheus.io/scrape"].as<std::string>(), "true");
  EXPECT_EQ(ann["prometheus.io/port"].as<std::string>(), flag["--metrics-port"]);
  EXPECT_EQ(ann["prometheus.io/path"].as<std::string>(), "/metrics");
  // The snapshot folder is the shared ReadWriteMany claim.
  std::string claim;
  for (const auto& m : c["volumeMounts"])
    if (m["mountPath"].as<std::string>() == flag["--snapshot-dir"])
      for (const auto& v : pod["spec"]["volumes"])
        if (v["name"].as<std::string>() == m["name"].as<std::string>()) claim = v["persistentVolumeClaim"]["claimName"].as<std::string>();
  ASSERT_FALSE(claim.empty()) << "--snapshot-dir " << flag["--snapshot-dir"] << " is not a mounted claim";
  const YAML::Node pvc = find_kind(base, "PersistentVolumeClaim", claim);
  ASSERT_TRUE(pvc) << claim;
  EXPECT_EQ(pvc["spec"]["accessModes"][0].as<std::string>(), "ReadWriteMany");
  // Config from the ConfigMap: every $(VAR) in the args is defined; the admin key from a Secret.
  std::set<std::string> defined;
  for (const auto& e : c["env"]) defined.insert(e["name"].as<std::string>());
  for (const auto& ef : c["envFrom"]) {
    const YAML::Node cm = find_kind(base, "ConfigMap", ef["configMapRef"]["name"].as<std::string>());
    ASSERT_TRUE(cm) << "ConfigMap " << ef["configMapRef"]["name"];
    for (const auto& kv : cm["data"]) defined.insert(kv.first.as<std::string>());
  }
  const std::regex var(R"(\$\(([A-Z_]+)\))");
  for (std::sregex_iterator it(args_text.begin(), args_text.end(), var), end; it != end; ++it)
    EXPECT_TRUE(defined.count((*it)[1].str())) << "$(" << (*it)[1] << ") is not defined";
  bool admin_from_secret = false;
  for (const auto& e : c["env"])
    if (e["name"].as<std::string>() == "RRG_ADMIN_KEY" && e["valueFrom"]["secretKeyRef"]["name"]) admin_from_secret = true;
  EXPECT_TRUE(admin_from_secret);
  EXPECT_TRUE(pod["spec"]["securityContext"]["runAsNonRoot"].as<bool>());
  // The Service selects the pods and names the gRPC port the ingress uses.
  const YAML::Node svc = find_kind(base, "Service", "rrg");
  ASSERT_TRUE(svc);
  for (const auto& kv : svc["spec"]["selector"])
    EXPECT_EQ(pod["metadata"]["labels"][kv.first.as<std::string>()].as<std::string>(), kv.second.as<std::string>());
}

TEST(Manifests, IngressRoutesGrpcByTheSessionHeader) {
  const fs::path base = kDeploy / "k8s/base";
  const YAML::Node ing = find_kind(base, "Ingress");
  ASSERT_TRUE(ing);
  const YAML::Node ann = ing["metadata"]["annotations"];
  EXPECT_EQ(ann["nginx.ingress.kubernetes.io/backend-protocol"].as<std::string>(), "GRPC");
  EXPECT_EQ(ann["nginx.ingress.kubernetes.io/upstream-hash-by"].as<std::string>(), "$http_x_rrg_session");
  EXPECT_EQ(ing["spec"]["ingressClassName"].as<std::string>(), "nginx");
  EXPECT_TRUE(ing["spec"]["tls"][0]["secretName"]);
  const YAML::Node backend = ing["spec"]["rules"][0]["http"]["paths"][0]["backend"]["service"];
  const YAML::Node svc = find_kind(base, "Service", backend["name"].as<std::string>());
  ASSERT_TRUE(svc) << "the ingress's backend service does not exist";
  bool port_found = false;
  for (const auto& p : svc["spec"]["ports"])
    if (p["name"].as<std::string>() == backend["port"]["name"].as<std::string>()) port_found = true;
  EXPECT_TRUE(port_found);
}

TEST(Manifests, ComposeReservesAGpuAndDockerfileIsMultiStageNonRoot) {
  const YAML::Node compose = YAML::LoadFile((kDeploy / "compose.yaml").string());
  const YAML::Node rrg = compose["services"]["rrg"];
  ASSERT_TRUE(rrg);
  const YAML::Node dev = rrg["deploy"]["resources"]["reservations"]["devices"][0];
  EXPECT_EQ(dev["driver"].as<std::string>(), "nvidia");
  EXPECT_EQ(dev["count"].as<int>(), 1);
  EXPECT_EQ(dev["capabilities"][0].as<std::string>(), "gpu");
  EXPECT_TRUE(rrg["healthcheck"]["test"]);
  std::set<std::string> ports;
  for (const auto& p : rrg["ports"]) ports.insert(p.as<std::string>());
  EXPECT_TRUE(ports.count("50051:50051") && ports.count("8080:8080")) << "gRPC and viewer ports";
  EXPECT_EQ(rrg["build"]["dockerfile"].as<std::string>(), "deploy/Dockerfile");

  const std::string docker = read_text(kDeploy / "Dockerfile");
  const std::regex from(R"(^FROM\s+\S+\s+AS\s+(\w+))", std::regex::multiline | std::regex::icase);
  std::set<std::string> stages;
  for (std::sregex_iterator it(docker.begin(), docker.end(), from), end; it != end; ++it) stages.insert((*it)[1]);
  EXPECT_TRUE(stages.count("build") && stages.count("runtime")) << "multi-stage: build and runtime";
  EXPECT_TRUE(std::regex_search(docker, std::regex(R"(^USER\s+10001)", std::regex::multiline))) << "non-root user";
  EXPECT_TRUE(std::regex_search(docker, std::regex(R"(^HEALTHCHECK .*\n?.*rrg.*health)", std::regex::multiline)));
  EXPECT_NE(docker.find("scripts/install_deps.sh"), std::string::npos);
}

TEST(Manifests, NginxTemplatePassesNginxT) {
  const std::string nginx = find_nginx();
  ASSERT_FALSE(nginx.empty()) << "nginx not found: run scripts/install_deps.sh (Debian package nginx)";
  TempDir dir("rrg-nginx-t");
  for (const char* d : {"client_body", "proxy", "fastcgi", "uwsgi", "scgi"}) fs::create_directories(dir / d);
  std::ofstream(dir / "nginx.conf") << render_nginx_conf(dir.path(), "127.0.0.1:" + std::to_string(free_port()),
                                                         {"127.0.0.1:50051", "127.0.0.1:50052", "127.0.0.1:50053"});
  const auto [rc, out] = run_shell(nginx + " -t -p " + dir.path().string() + " -c " + (dir / "nginx.conf").string());
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("test is successful"), std::string::npos) << out;
}

TEST(Manifests, DockerComposeConfigWhenDockerComposeExists) {
  const auto [has, version] = run_shell("docker compose version");
  if (has != 0) GTEST_SKIP() << "docker compose not available here (" << version.substr(0, 80) << "): not checked";
  const auto [rc, out] = run_shell("RRG_ADMIN_KEY=test docker compose -f " + (kDeploy / "compose.yaml").string() +
                                   " config --quiet");
  EXPECT_EQ(rc, 0) << out;
}

}  // namespace
}  // namespace rrg::test
