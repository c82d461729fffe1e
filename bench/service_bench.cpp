// service_bench: what distribution costs on this machine. Renders one job
//   (1) embedded: prepareLights + all tiles in this process, all cores;
//   (2) through an in-process coordinator (real gRPC on loopback) and K
//       vrl-worker processes, for each K in --workers (threads per worker =
//       cores / K), timed from submission to the finished EXR;
// and prints each run's shading throughput relative to the embedded one
// (parallel efficiency), the light-tree broadcast rate (a worker's verified
// download of the serialised tree, MB/s) and the coordinator's time per tile
// in its lease and submit handlers. Wall-clock, one run each: compare ratios.
#include "client/job_client.h"
#include "render/core/timing.h"
#include "render/description/scene_description.h"
#include "server/coordinator_service.h"
#include "service/job/job_scene.h"
#include "util/command_line.h"
#include "util/random_id.h"
#include "worker/asset_fetcher.h"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>
#include <tbb/info.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <thread>
#include <tuple>

extern char** environ;

using namespace vrl;
using namespace vrl::client;
namespace fs = std::filesystem;

namespace {

pid_t spawnWorker(const std::string& program, const std::string& address, int threads, int index) {
    const std::vector<std::string> arguments = {program, "--coordinator", address, "--threads", std::to_string(threads),
                                                "--name", "bench-" + std::to_string(index), "--log-level", "warn"};
    std::vector<char*> argv;
    for (const auto& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = 0;
    if (posix_spawn(&pid, program.c_str(), nullptr, nullptr, argv.data(), environ) != 0)
        throw std::runtime_error("cannot start " + program);
    return pid;
}

// A coordinator serving on 127.0.0.1:<free port> with a temporary state directory.
struct LoopbackCoordinator {
    explicit LoopbackCoordinator(const std::string& token)
        : state(fs::temp_directory_path() / ("vrl-service-bench-" + util::randomHex(12))),
          coordinator(optionsFor(state)),
          server(coordinator, server::ServerOptions{"127.0.0.1:0", {}, token}),
          address("127.0.0.1:" + std::to_string(server.port())) {}
    ~LoopbackCoordinator() {
        server.shutdown(std::chrono::milliseconds(0));
        std::error_code error;
        fs::remove_all(state, error);
    }
    static server::CoordinatorOptions optionsFor(const fs::path& state) {
        server::CoordinatorOptions options;
        options.stateDir = state;
        return options;
    }
    fs::path state;
    server::Coordinator coordinator;
    server::CoordinatorServer server;
    std::string address;
};

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"service_bench: embedded render against K worker processes; tree broadcast rate; coordinator "
                 "overhead per tile"};
    std::string scene = VRL_DEFAULT_SCENE, method = "vrl-lightcuts", resolution = "160x120";
    std::string workerProgram = VRL_WORKER_PROGRAM;
    std::vector<int> workerCounts = {1, 2};
    uint64_t vrls = 20000;
    int spp = 4, tileSize = 16;
    app.add_option("--scene", scene, "Scene file")->capture_default_str();
    app.add_option("--method", method, "path, vrl or vrl-lightcuts")->capture_default_str();
    app.add_option("--resolution", resolution, "WxH")->capture_default_str();
    app.add_option("--spp", spp, "Samples per pixel")->capture_default_str();
    app.add_option("--vrls", vrls, "VRLs")->capture_default_str();
    app.add_option("--tile-size", tileSize, "Tile side")->capture_default_str();
    app.add_option("--workers", workerCounts, "Worker process counts to run")->capture_default_str();
    app.add_option("--worker-program", workerProgram, "The vrl-worker executable")->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    spdlog::set_level(spdlog::level::warn);

    int width = 0, height = 0;
    try {
        std::tie(width, height) = util::parseResolution(resolution, kMaxFilmSide, kMaxFilmPixels);
    } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
    }
    v1::JobSpec spec;
    auto& p = *spec.mutable_parameters();
    p = rpc::defaultRenderParameters(parseRenderMethod(method));
    p.set_samples_per_pixel(spp);
    p.set_width(uint32_t(width));
    p.set_height(uint32_t(height));
    p.set_vrl_count(vrls);
    spec.set_tile_size(uint32_t(tileSize));
    spec.set_name(scene);
    const int cores = tbb::info::default_concurrency();

    // (1) Embedded.
    rpc::JobScene job = rpc::loadJobScene(fs::path(scene).parent_path(), scene, spec, rpc::ServiceLimits{});
    RenderStatistics embeddedStats;
    auto start = std::chrono::steady_clock::now();
    (void)render(*job.scene, job.settings, {}, &embeddedStats);
    const double embeddedTotal = secondsSince(start);
    const double embeddedShading = embeddedStats.seconds;
    std::printf("service_bench: %s, %s, %s, %d spp, %llu VRLs, tiles %d, %d cores\n", scene.c_str(), method.c_str(),
                resolution.c_str(), spp, (unsigned long long)vrls, tileSize, cores);
    std::printf("%-22s %10s %10s %12s %12s\n", "run", "total s", "shading s", "efficiency", "overhead/tile");
    std::printf("%-22s %10.3f %10.3f %12s %12s\n", "embedded", embeddedTotal, embeddedShading, "1.000", "-");

    const std::string token = util::randomHex(32);
    setenv("VRL_TOKEN", token.c_str(), 1);  // the worker processes read it
    for (const int count : workerCounts) {
        {
            LoopbackCoordinator local(token);
            const std::string& address = local.address;
            std::vector<pid_t> workers;
            for (int w = 0; w < count; ++w)
                workers.push_back(spawnWorker(workerProgram, address, std::max(1, cores / count), w + 1));
            std::this_thread::sleep_for(std::chrono::milliseconds(300));  // registered and idle
            JobClient client(address, {}, token);
            start = std::chrono::steady_clock::now();
            v1::JobSpec submitted = spec;
            submitted.set_bundle_sha256(client.uploadBundle(collectSceneBundle(scene, {})));
            const std::string id = client.submit(submitted);
            const v1::JobProgress last = client.watch(id, {});
            client.fetchImage(id, local.state / "image.exr");
            const double total = secondsSince(start);
            double shading = 0.0;
            for (const auto& phase : last.phases())
                if (phase.phase() == "render") shading = phase.seconds();
            const auto stats = local.coordinator.statistics();
            const double overhead = (stats.leaseSeconds + stats.submitSeconds) / double(std::max<uint64_t>(1, stats.tilesAccepted));
            char name[64];
            std::snprintf(name, sizeof name, "%d worker%s x %d thr", count, count > 1 ? "s" : "", std::max(1, cores / count));
            std::printf("%-22s %10.3f %10.3f %12.3f %10.1f us\n", name, total, shading, embeddedShading / shading,
                        overhead * 1e6);
            for (const pid_t pid : workers) kill(pid, SIGTERM);
            for (const pid_t pid : workers) waitpid(pid, nullptr, 0);
        }
    }

    // Broadcast rate: a worker's verified download (chunks, CRC-32, SHA-256) of a serialised tree.
    {
        {
            LoopbackCoordinator local(token);
            server::Coordinator& coordinator = local.coordinator;
            JobClient client(local.address, {}, token);
            v1::JobSpec big = spec;
            big.mutable_parameters()->set_method("vrl-lightcuts");
            big.mutable_parameters()->set_vrl_count(std::max<uint64_t>(vrls, 200000));
            big.set_bundle_sha256(client.uploadBundle(collectSceneBundle(scene, {})));
            const std::string id = client.submit(big);
            v1::RegisterRequest hello;
            hello.set_protocol_version(rpc::kProtocolVersion);
            hello.set_program_version(VRL_VERSION);
            hello.set_threads(1);
            v1::LeaseRequest ask;
            ask.set_worker_id(coordinator.registerWorker(hello).worker_id());
            v1::LeaseReply lease;
            while (lease.jobs_size() == 0) {
                std::this_thread::sleep_for(std::chrono::milliseconds(20));
                lease = coordinator.leaseTiles(ask);
            }
            const auto& assets = lease.jobs(0);
            worker::AssetFetcher fetcher(rpc::makeChannel(local.address, {}), token);
            start = std::chrono::steady_clock::now();
            const std::string blob = fetcher.fetch(assets.lights_sha256(), assets.lights_size());
            const double seconds = secondsSince(start);
            std::printf("tree broadcast: %.1f MB (%llu VRLs) fetched and verified in %.3f s: %.0f MB/s per worker\n",
                        double(blob.size()) / 1e6, (unsigned long long)big.parameters().vrl_count(), seconds,
                        double(blob.size()) / 1e6 / seconds);
            coordinator.cancelJob(id);
        }
    }
    return 0;
}
