// The sweep's report (docs/diff-and-compare.md): sweep.csv, sweep.json, four Pareto plots per
// scenario and the text table, from a finished plan (sweep_engine.h), whether it ran in one
// process or was merged from shards (sweep_shards.h): the same plan gives the same bytes.
#pragma once

#include <string>
#include <vector>

#include "replay/cli/sweep_engine.h"

namespace sg::sweep {

/// Creates `out` when missing and checks that no output (sweep.csv, sweep.json, the plots) would
/// replace a scenario or a file one of them reads. False with one line on stderr.
bool checkOutputs(const Plan& plan, const std::string& out);

/// Writes sweep.csv, sweep.json and the plots into `out`, then prints the table (or, with `json`,
/// sweep.json) on stdout. Returns the exit code: 0, 1 when a variant faulted, 2 on a write error.
int writeReport(const Plan& plan, const std::string& out, bool json);

}  // namespace sg::sweep
