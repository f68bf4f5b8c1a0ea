// cli/main.cpp — cloudgen: entry point, signals, exit codes.
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/events.h"
#include "cloudgen/grid.h"
#include "cloudgen/names.h"
#include "cloudgen/param_io.h"
#include "io/atomic_file.h"
#include "io/vdb_sandbox.h"

namespace cli {

namespace {
volatile std::sig_atomic_t g_signals = 0;

// First SIGINT/SIGTERM: ask the running bake to stop (it unwinds and removes
// its temporary file). A second one: remove the temporaries now and exit.
extern "C" void on_signal(int) {
  g_signals = g_signals + 1;
  if (g_signals >= 2) {
    cgio::remove_temporaries_signal_safe();
    static const char msg[] = "cloudgen: cancelled\n";
    (void)!::write(2, msg, sizeof msg - 1);
    ::_exit(kExitCancelled);
  }
}

void install_signal_handlers() {
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  // Past a file-size limit, let write() fail with EFBIG (reported, temporaries
  // removed) instead of being killed with the temporary file left behind.
  std::signal(SIGXFSZ, SIG_IGN);
}
}  // namespace

bool cancel_requested() { return g_signals != 0; }

const char* const kUsage =
    "usage: cloudgen [--help] [--version [--json]] COMMAND [ARGS]\n"
    "\n"
    "Procedural volumetric clouds: bakes the cloud model to OpenVDB and writes\n"
    "cross-section previews.\n"
    "\n"
    "commands:\n"
    "  bake      evaluate the density on a voxel grid, write FILE.vdb (or a sequence)\n"
    "  merge     join the bricks of a split bake (bake --brick I/N) into one FILE.vdb\n"
    "  preview   write a 2D cross-section through the cloud box as PNG or EXR\n"
    "  presets   list the cloud types\n"
    "  tiers     list the quality tiers (Draft, Preview, Final) for bake --quality\n"
    "  params    list the parameters a --params FILE.json may set (--json for JSON)\n"
    "  info      describe a VDB file: grids, class, voxel size, active voxels, metadata\n"
    "\n"
    "`cloudgen COMMAND --help` explains each command. Parameters come from a preset\n"
    "(--preset NAME) or a JSON parameter file (--params FILE.json).\n"
    "\n"
    "examples:\n"
    "  cloudgen bake --preset cumulus --resolution 128 --output cumulus.vdb\n"
    "  cloudgen bake --params my.json --resolution 96 --frames 1-48 --fps 24 --output cloud_####.vdb\n"
    "  cloudgen bake --preset cumulus --quality preview --camera shot.json --output shot.vdb\n"
    "  cloudgen preview --preset cumulus --axis y --offset 0.5 --size 512 --output slice.png\n"
    "\n"
    "machine-readable output: `bake` and `preview` take --json (one JSON object per\n"
    "line on stdout; docs/cli_protocol.md); `cloudgen --version --json` names the protocol.\n"
    "\n"
    "exit codes: 0 ok; 1 runtime failure (I/O); 2 bad usage or argument (one line\n"
    "`cloudgen: error: ...` naming it); 130 cancelled by SIGINT/SIGTERM (no partial file).\n";

}  // namespace cli

namespace {

int fail(int code, const std::string& message) {
  // Values in messages are clipped where they are quoted; this caps the whole line.
  cli::report_error(code, cli::clipped(cli::one_line(message), 1000));
  return code;
}

int print_version(const std::vector<std::string>& rest) {
  if (rest.size() > 1 || (rest.size() == 1 && rest[0] != "--json"))
    throw cli::UsageError("--version takes only --json");
  if (rest.empty()) {
    std::cout << "cloudgen " << cg::version() << " (protocol " << cg::kProtocolVersion << ")\n";
  } else {
    const nlohmann::json v = {{"version", cg::version()}, {"protocol", cg::kProtocolVersion}};
    std::cout << v.dump() << "\n";
  }
  return cli::kExitOk;
}

int run(const std::vector<std::string>& args) {
  using namespace cli;
  if (args.empty()) return fail(kExitUsage, "no command given (see `cloudgen --help`)");
  const std::string& verb = args[0];
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (verb == "--help" || verb == "-h" || verb == "help") return std::cout << kUsage, kExitOk;
  if (verb == "--version") return print_version(rest);
  if (verb == "bake") return cmd_bake(rest);
  if (verb == "preview") return cmd_preview(rest);
  if (verb == "presets") return cmd_presets(rest);
  if (verb == "params") return cmd_params(rest);
  if (verb == "info") return cmd_info(rest);
  if (verb == "tiers") return cmd_tiers(rest);
  if (verb == "merge") return cmd_merge(rest);
  throw UsageError("unknown command '" + verb.substr(0, 100) +
                   "'; expected one of bake, merge, preview, presets, tiers, params, info" +
                   cg::did_you_mean(verb, {"bake", "merge", "preview", "presets", "tiers", "params", "info"}));
}

}  // namespace

int main(int argc, char** argv) {
  // The hidden verb of the limited child that reads an untrusted VDB (io/vdb_sandbox.h).
  if (argc == 3 && std::strcmp(argv[1], cgio::kVdbInfoChildVerb) == 0) return cgio::vdb_info_child_main(argv[2]);
  cli::install_signal_handlers();
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    const int code = run(args);
    std::fflush(stdout);
    return code;
  } catch (const cli::UsageError& e) {
    return fail(cli::kExitUsage, e.what());
  } catch (const cg::ParamError& e) {
    return fail(cli::kExitUsage, e.what());
  } catch (const cgio::OutputPathError& e) {
    return fail(cli::kExitUsage, e.what());
  } catch (const cg::Cancelled&) {
    return fail(cli::kExitCancelled, "cancelled (no file left behind for the unfinished output)");
  } catch (const cgio::IoError& e) {
    return fail(cli::kExitFailure, e.what());
  } catch (const std::bad_alloc&) {
    return fail(cli::kExitFailure, "out of memory (lower --resolution or raise --tolerance)");
  } catch (const std::exception& e) {
    return fail(cli::kExitFailure, e.what());
  }
}
