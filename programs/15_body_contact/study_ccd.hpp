#pragma once
// Study 2 of ch15_body_contact: the two primitive CCD methods (15_body_contact/ccd.hpp) on the queries of the
// public CCD benchmark; its own header so that main.cpp can run it alone (--ccd-queries).
// Not part of the chapter's library: only the executable uses it.

#include "common/cli.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace fem::contact::study {

/// The benchmark's unit-test query files kept in the project: data/ccd-unit-tests/vertex-face/ and
/// edge-edge/, data_0_0.csv and data_0_1.csv of each.
std::vector<std::string> ccd_benchmark_files();

/// The check of a --ccd-queries file: fem::Error when it does not exist, its folder does not say what
/// it holds (ccd_query_pair) or it does not read (read_ccd_queries).
void check_ccd_query_file(const std::string& file);

/// Runs cubic_ccd and inclusion_ccd (default settings) on every query of every file and writes
/// ccd_queries_table.csv: per file and method the queries, the collisions reported, the false
/// negatives and false positives against the file's truth, and the median and mean time per query
/// (per query, the best of a few batches of calls, divided by the calls in a batch) [µs].
void ccd_study(const RunContext& run, const std::vector<std::string>& files);

}  // namespace fem::contact::study
