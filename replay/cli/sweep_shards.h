// A sweep split into independent jobs for the schedulers a team already has (docs/scale-out.md):
// GNU parallel, Slurm job arrays, Kubernetes indexed Jobs.
//
//   simgrass sweep [the usual options] --plan plan.json          writes the plan: its options, a
//                                                                fingerprint, the list of jobs
//   simgrass sweep --plan plan.json --job I --out shards/        runs job I, writes one shard
//   simgrass sweep --merge shards/ --out results/                checks every job is there once,
//                                                                writes today's CSV, JSON, plots
//
// Jobs 0 .. S-1 are the scenarios' references (the reference run, one tuft's behaviour and model
// errors); jobs S .. are the variants, each reading its scenario's reference shard, so sharding
// never runs a reference twice. A shard is written atomically under a name fixed by its job, so
// running a job again replaces its shard whole (idempotent). The plan's fingerprint covers the
// build, the options and the bytes of every scenario and file it reads: a shard of another plan,
// another build or changed inputs is refused by name.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>

#include "replay/cli/sweep_engine.h"

namespace sg::sweep {

/// The fingerprint of a plan: xxHash3 (hex) over the build id, the options and the bytes of every
/// scenario file and every file the scenarios embed, in plan order.
std::string fingerprintOf(const Plan& plan);

/// Jobs: one reference per scenario, then one per row.
inline int64_t jobCount(const Plan& plan) { return int64_t(plan.scenarios.size() + plan.rows.size()); }
inline int64_t referenceJobs(const Plan& plan) { return int64_t(plan.scenarios.size()); }
/// "reference of sweep-bodies" / "sweep-bodies: scalar=fx16 interp=2 dt=1/60 lod=off broadphase=grid".
std::string jobName(const Plan& plan, int64_t job);
/// The shard file of a job: DIR/shard-NNNNNN.sgs.
std::string shardPath(const std::string& dir, int64_t job);

/// Writes the plan file (atomically). False with one line on stderr.
bool writePlan(const Plan& plan, const std::string& path);

/// Reads a plan file and rebuilds its plan (the scenario files are read again, relative to the
/// working folder, as when it was written). Throws std::runtime_error with one line: the file, the
/// JSON path and what was expected, or that the build or the inputs are not the plan's.
Plan readPlan(const std::string& path, std::string* fingerprint);

/// What a merge needs of a plan file: its options, scenarios (file, name, model, inputs) and
/// fingerprint, without reading a scenario file (the shards hold the results; the inputs may
/// since have changed or be elsewhere). Throws std::runtime_error with one line.
Plan readPlanForMerge(const std::string& path, std::string* fingerprint);

/// The job index: `text` is a number, or "env": SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX
/// (Kubernetes indexed Jobs) or PARALLEL_SEQ - 1 (GNU parallel's {#}), the first one set. Plus
/// `offset`. Throws std::invalid_argument with one line.
int64_t jobIndex(const std::string& text, int64_t offset, int64_t jobs);

/// Runs job `job` of `plan` and writes its shard (and a copy of the plan file, for the merge)
/// into `dir`. Returns the exit code: 0 (a variant that faulted is a result, in its shard), 1 the
/// reference faulted or its shard could not be written, 2 a variant's reference shard is missing
/// or damaged. Prints progress unless `quiet`.
int runJob(Plan& plan, const std::string& fingerprint, int64_t job, const std::string& dir, bool quiet);

/// Reads every shard of `dir` into `plan` (its references' results and its rows' measurements),
/// checking that each job is there exactly once and that every shard is of this plan and intact.
/// False with *error: one line naming the job or the file (and the byte offset).
bool mergeShards(Plan& plan, const std::string& fingerprint, const std::string& dir, std::string* error);

}  // namespace sg::sweep
