// cli/merge.cpp — `cloudgen merge`: the bricks of a split bake into one VDB.
#include <iostream>

#include "cli/commands.h"
#include "cli/events.h"
#include "io/atomic_file.h"
#include "io/vdb_io.h"

namespace cli {

namespace {

const char* const kMergeHelp =
    "usage: cloudgen merge --output FILE.vdb [--json] BRICK.vdb...\n"
    "\n"
    "Joins the bricks of one split bake (`cloudgen bake --brick I/N`, all N of them,\n"
    "in any order) into one VDB equal, voxel for voxel, to the whole bake, with the\n"
    "whole bake's key (so `bake --update` keeps it). Reads one brick at a time: memory\n"
    "is the sparse result plus one brick. A missing, repeated or foreign brick is\n"
    "refused with one line naming it; the output is written atomically.\n"
    "\n"
    "  --output FILE.vdb   the merged file\n"
    "  --json              one `wrote` (or `error`) JSON line (docs/cli_protocol.md)\n";

}  // namespace

int cmd_merge(const std::vector<std::string>& argv) {
  if (std::find(argv.begin(), argv.end(), "--json") != argv.end()) set_output_mode(OutputMode::Json);
  Args a("merge", argv, {{"--output", true}, {"--json", false}});
  if (a.help()) return std::cout << kMergeHelp, kExitOk;
  const std::string output = a.text("--output");
  if (a.positional().empty()) throw UsageError("merge: give the brick files to merge");
  cgio::check_output_path(output);
  const auto t0 = std::chrono::steady_clock::now();
  cgio::AtomicFile file(output);
  cgio::MergeStats stats;
  file.write_with([&](const std::string& tmp) { stats = cgio::merge_vdb_bricks(a.positional(), tmp); });
  if (cancel_requested()) throw cg::Cancelled();
  file.commit();
  const double seconds = seconds_since(t0);
  emit("wrote",
       {{"path", output},
        {"bricks", stats.bricks},
        {"active_voxels", stats.active_voxels},
        {"bytes", cgio::file_size(output)},
        {"seconds", seconds}},
       "wrote " + output + " (" + std::to_string(stats.bricks) + " bricks, " + std::to_string(stats.active_voxels) +
           " active voxels)");
  return kExitOk;
}

}  // namespace cli
