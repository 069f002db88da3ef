// dmc view: decode a .dmc stream to GLB and serve the viewer page (tools/viewer) on 127.0.0.1,
// showing the original (when given) and the decoded animation side by side, the decoded one
// coloured by per-vertex error, with each frame's KG/STED contribution and the file's bpfv.
//
// The server is a few lines of POSIX sockets rather than `python3 -m http.server` so that dmc
// needs no interpreter, binds to the loopback address only, and serves exactly five in-memory
// files (anything else is 404: no directory listing, no path traversal). It opens nothing else:
// no browser is launched, the URL is printed.
#include <arpa/inet.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>

#include "cli_util.h"
#include "commands.h"
#include "dmc/decoder.h"
#include "dmc/io.h"
#include "dmc/metrics.h"

namespace dmc::cli {
namespace {

struct ViewArgs {
  std::string input;
  std::string original;
  std::string viewer_dir;
  int port = 0;
  double exit_after = 0.0;
  GltfReadFlags gltf;
  bool json = false;
};

struct ServedFile {
  std::string content_type;
  std::string body;
};

std::atomic<bool> g_stop{false};
extern "C" void HandleStopSignal(int) { g_stop = true; }

// Where the built viewer (index.html + viewer.js) lives: --viewer-dir, $DMC_VIEWER_DIR, then
// beside the executable (bin/viewer, as the build puts it) or ../share/dmc/viewer (installed).
StatusOr<std::filesystem::path> FindViewerDir(const std::string& given) {
  std::vector<std::filesystem::path> candidates;
  if (!given.empty()) {
    candidates.emplace_back(given);
  } else {
    if (const char* env = std::getenv("DMC_VIEWER_DIR"); env != nullptr && *env != '\0') {
      candidates.emplace_back(env);
    }
    std::error_code error;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
    if (!error) {
      candidates.push_back(exe.parent_path() / "viewer");
      candidates.push_back(exe.parent_path().parent_path() / "share" / "dmc" / "viewer");
    }
  }
  for (const auto& dir : candidates) {
    std::error_code error;
    if (std::filesystem::is_regular_file(dir / "index.html", error) &&
        std::filesystem::is_regular_file(dir / "viewer.js", error)) {
      return dir;
    }
  }
  return IoError("the viewer is not built: no index.html + viewer.js in " +
                 (candidates.empty() ? std::string("--viewer-dir") : candidates.front().string()) +
                 " (build it with tools/viewer/build.sh <build>/bin/viewer, or pass --viewer-dir)");
}

StatusOr<std::string> ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError("cannot read " + path.string());
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The GLB bytes of a sequence, written through WriteSequence into a scratch directory.
StatusOr<std::string> ToGlb(const MeshSequence& sequence, const std::filesystem::path& scratch,
                            const std::string& name) {
  const std::filesystem::path path = scratch / (name + ".glb");
  // The page reads the frames straight from the buffers (tools/viewer/src/frames.js): float32,
  // frame-0-relative targets; the files never leave this machine, so size does not matter.
  WriteOptions options;
  options.glb_encoding = "float";
  DMC_RETURN_IF_ERROR(WriteSequence(sequence, path, options));
  return ReadText(path);
}

// Per-frame KG contribution (100·‖A_f − A′_f‖ / ‖A − E(A)‖, so the squares add up to KG²) and
// per-frame spatial STED (the mean over vertices of dev(v) in that frame; STED_s is their mean).
StatusOr<nlohmann::json> FrameMetrics(const MeshSequence& original, const MeshSequence& decoded) {
  DMC_ASSIGN_OR_RETURN(const DistortionReport totals, MeasureDistortion(original, decoded));
  double spread = 0.0;
  std::vector<double> frame_error(static_cast<size_t>(original.frame_count()), 0.0);
  for (int f = 0; f < original.frame_count(); ++f) {
    const FramePositionsD a = original.frame_d(f);
    const FramePositionsD b = decoded.frame_d(f);
    spread += (a.rowwise() - a.colwise().mean()).squaredNorm();
    frame_error[static_cast<size_t>(f)] = (a - b).squaredNorm();
  }
  nlohmann::json frames = nlohmann::json::array();
  for (int f = 0; f < original.frame_count(); ++f) {
    MeshSequence original_frame(original.vertex_count(), original.triangles(), 1);
    MeshSequence decoded_frame(decoded.vertex_count(), decoded.triangles(), 1);
    original_frame.frame(0) = original.frame(f);
    decoded_frame.frame(0) = decoded.frame(f);
    DMC_ASSIGN_OR_RETURN(const StedResult sted, Sted(original_frame, decoded_frame));
    const double kg =
        spread > 0 ? 100.0 * std::sqrt(frame_error[static_cast<size_t>(f)] / spread) : 0.0;
    frames.push_back({{"kg", kg}, {"sted_s", sted.sted_s}});
  }
  return nlohmann::json{
      {"kg", totals.kg},         {"sted", totals.sted},         {"sted_s", totals.sted_s},
      {"sted_t", totals.sted_t}, {"rmse_rel", totals.rmse_rel}, {"max_error", totals.max_error},
      {"frames", frames}};
}

void SendAll(int socket, const std::string& bytes) {
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(socket, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return;
    sent += static_cast<size_t>(n);
  }
}

void Respond(int socket, const std::map<std::string, ServedFile>& files) {
  // Requests are a line and a few headers; anything bigger than 16 KiB is not one of ours.
  std::string request;
  char buffer[4096];
  while (request.find("\r\n\r\n") == std::string::npos && request.size() < 16384) {
    const ssize_t n = ::recv(socket, buffer, sizeof(buffer), 0);
    if (n <= 0) break;
    request.append(buffer, static_cast<size_t>(n));
  }
  std::istringstream line(request.substr(0, request.find("\r\n")));
  std::string method, target;
  line >> method >> target;
  target = target.substr(0, target.find('?'));
  if (target == "/") target = "/index.html";
  const auto file = files.find(target);
  std::string head;
  const std::string* body = nullptr;
  static const std::string kNotFound = "not found\n";
  if ((method == "GET" || method == "HEAD") && file != files.end()) {
    head = fmt::format("HTTP/1.1 200 OK\r\nContent-Type: {}\r\nContent-Length: {}\r\n",
                       file->second.content_type, file->second.body.size());
    body = &file->second.body;
  } else {
    head = fmt::format(
        "HTTP/1.1 404 Not Found\r\nContent-Type: text/plain\r\n"
        "Content-Length: {}\r\n",
        kNotFound.size());
    body = &kNotFound;
  }
  head += "Cache-Control: no-store\r\nConnection: close\r\n\r\n";
  SendAll(socket, head);
  if (method != "HEAD") SendAll(socket, *body);
  ::close(socket);
}

int RunView(const ViewArgs& args) {
  auto viewer_dir = FindViewerDir(args.viewer_dir);
  if (!viewer_dir.ok()) return ReportError("view", viewer_dir.status(), args.json);
  WarnIfGltfOptionsUnused("view", args.gltf, {args.original});
  auto bytes = ReadFileBytes(args.input);
  if (!bytes.ok()) return ReportError("view", bytes.status(), args.json);
  StatusOr<MeshSequence> decoded = Decode(*bytes);
  if (!decoded.ok())
    return ReportError("view", decoded.status().WithContext(args.input), args.json);

  std::optional<MeshSequence> original;
  if (!args.original.empty()) {
    ReadOptions read_options;
    read_options.gltf = args.gltf.options;
    ReadReport report;
    StatusOr<MeshSequence> read = ReadSequence(args.original, read_options, &report);
    if (!read.ok()) return ReportError("view", read.status(), args.json);
    if (!args.json) {
      for (const std::string& warning : report.warnings) ReportWarning("view", warning);
    }
    const Status comparable = CheckComparable(*read, *decoded);
    if (!comparable.ok()) {
      return ReportError("view", comparable.WithContext(args.original + " vs " + args.input),
                         args.json);
    }
    original = std::move(read).value();
  }

  std::error_code error;
  const std::filesystem::path scratch =
      std::filesystem::temp_directory_path(error) / fmt::format("dmc-view-{}", ::getpid());
  std::filesystem::create_directories(scratch, error);
  if (error) return ReportError("view", IoError("cannot create " + scratch.string()), args.json);
  struct RemoveScratch {
    std::filesystem::path path;
    ~RemoveScratch() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  } remove_scratch{scratch};

  std::map<std::string, ServedFile> files;
  for (const char* name : {"index.html", "viewer.js"}) {
    auto text = ReadText(*viewer_dir / name);
    if (!text.ok()) return ReportError("view", text.status(), args.json);
    files[std::string("/") + name] = {
        std::string(name).ends_with(".js") ? "text/javascript" : "text/html; charset=utf-8",
        std::move(text).value()};
  }
  // The WebAssembly decoder, when the viewer was built with it (tools/viewer/build.sh copies web/'s
  // package into wasm/): the page then decodes the stream itself, else it reads decoded.glb.
  bool in_page = true;
  for (const char* name : {"dmc.js", "dmc_decoder.js", "dmc_decoder.wasm"}) {
    in_page = in_page && std::filesystem::is_regular_file(*viewer_dir / "wasm" / name, error);
  }
  if (in_page) {
    for (const char* name : {"dmc.js", "dmc_decoder.js", "dmc_decoder.wasm"}) {
      auto body = ReadText(*viewer_dir / "wasm" / name);
      if (!body.ok()) return ReportError("view", body.status(), args.json);
      files[std::string("/wasm/") + name] = {
          std::string(name).ends_with(".js") ? "text/javascript" : "application/wasm",
          std::move(body).value()};
    }
    files["/data/stream.dmc"] = {"application/octet-stream",
                                 std::string(bytes->begin(), bytes->end())};
  } else {
    auto decoded_glb = ToGlb(*decoded, scratch, "decoded");
    if (!decoded_glb.ok()) return ReportError("view", decoded_glb.status(), args.json);
    files["/data/decoded.glb"] = {"model/gltf-binary", std::move(decoded_glb).value()};
  }
  const double bpfv = 8.0 * static_cast<double>(bytes->size()) /
                      (static_cast<double>(decoded->frame_count()) * decoded->vertex_count());
  nlohmann::json metrics = {{"input", std::filesystem::path(args.input).filename().string()},
                            {"bpfv", bpfv},
                            {"bytes", bytes->size()},
                            {"frames", decoded->frame_count()},
                            {"vertices", decoded->vertex_count()},
                            {"frame_rate", decoded->frame_rate > 0 ? decoded->frame_rate : 30.0},
                            {"original", nullptr},
                            {"stream", in_page ? nlohmann::json("data/stream.dmc") : nullptr}};
  if (original) {
    auto original_glb = ToGlb(*original, scratch, "original");
    if (!original_glb.ok()) return ReportError("view", original_glb.status(), args.json);
    files["/data/original.glb"] = {"model/gltf-binary", std::move(original_glb).value()};
    auto measured = FrameMetrics(*original, *decoded);
    if (!measured.ok()) return ReportError("view", measured.status(), args.json);
    metrics["original"] = std::filesystem::path(args.original).filename().string();
    metrics["distortion"] = std::move(measured).value();
  }
  files["/data/metrics.json"] = {"application/json", JsonText(metrics)};

  const int listener = ::socket(AF_INET, SOCK_STREAM, 0);
  if (listener < 0) return ReportError("view", IoError("cannot create a socket"), args.json);
  const int reuse = 1;
  ::setsockopt(listener, SOL_SOCKET, SO_REUSEADDR, &reuse, sizeof(reuse));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(args.port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // never reachable from another machine
  if (::bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
      ::listen(listener, 64) != 0) {
    ::close(listener);
    return ReportError("view", IoError(fmt::format("cannot listen on 127.0.0.1:{}", args.port)),
                       args.json);
  }
  socklen_t length = sizeof(address);
  ::getsockname(listener, reinterpret_cast<sockaddr*>(&address), &length);
  const std::string url = fmt::format("http://127.0.0.1:{}/", ntohs(address.sin_port));
  if (args.json) {
    PrintJson({{"url", url}, {"frames", decoded->frame_count()}, {"bpfv", bpfv}});
  } else {
    fmt::print("serving {} ({} frames x {} vertices, {:.3f} bpfv) at {}\n", args.input,
               decoded->frame_count(), decoded->vertex_count(), bpfv, url);
    fmt::print("press Ctrl-C to stop\n");
  }
  std::fflush(stdout);

  std::signal(SIGINT, HandleStopSignal);
  std::signal(SIGTERM, HandleStopSignal);
  const auto files_shared =
      std::make_shared<const std::map<std::string, ServedFile>>(std::move(files));
  const auto started = std::chrono::steady_clock::now();
  // Accept with a timeout so Ctrl-C and --exit-after are noticed within 200 ms.
  const timeval tick{0, 200000};
  ::setsockopt(listener, SOL_SOCKET, SO_RCVTIMEO, &tick, sizeof(tick));
  while (!g_stop) {
    if (args.exit_after > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() >
            args.exit_after) {
      break;
    }
    const int client = ::accept(listener, nullptr, nullptr);
    if (client < 0) continue;
    // A stalled client (browsers open idle speculative connections) must not block the others.
    const timeval patience{5, 0};
    ::setsockopt(client, SOL_SOCKET, SO_RCVTIMEO, &patience, sizeof(patience));
    std::thread([client, files_shared] { Respond(client, *files_shared); }).detach();
  }
  ::close(listener);
  return 0;
}

}  // namespace

Command AddViewCommand(CLI::App& parent) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* app = parent.add_subcommand(
      "view", "Serve a viewer of a .dmc stream (and its original) on 127.0.0.1");
  app->add_option("-i,--input,INPUT", args->input, "Input .dmc file")->required();
  app->add_option("--original", args->original,
                  "The sequence that was encoded (any input dmc reads), shown beside the decoded "
                  "one and used for the error colours and KG/STED");
  app->add_option("--port", args->port, "TCP port on 127.0.0.1 (0 = any free port)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  app->add_option("--viewer-dir", args->viewer_dir,
                  "Directory holding the built viewer (index.html, viewer.js)");
  app->add_option("--exit-after", args->exit_after, "Stop serving after this many seconds")
      ->check(CLI::NonNegativeNumber);
  AddGltfReadOptions(app, &args->gltf, "glTF --original");
  app->add_flag("--json", args->json, "Print the URL as JSON");
  return {app, [args] { return RunView(*args); }};
}

}  // namespace dmc::cli
