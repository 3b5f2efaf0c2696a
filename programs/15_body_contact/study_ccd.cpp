// Study 2 of ch15_body_contact: continuous collision detection of a point and a triangle, or two edges,
// on the unit-test queries of the public CCD benchmark (Wang et al. 2021): the naive coplanarity
// cubic against the conservative inclusion method — their false negatives and false positives
// against the benchmark's truth, and their time per query. docs/15_body_contact.md#primitive-ccd
#include "study_ccd.hpp"

#include "15_body_contact/ccd.hpp"

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/table.hpp"
#include "common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numeric>

namespace fem::contact::study {

std::vector<std::string> ccd_benchmark_files()
{
    std::vector<std::string> files;
    for (const char* folder : {"vertex-face", "edge-edge"})
        for (const char* name : {"data_0_0.csv", "data_0_1.csv"})
            files.push_back(data_path(str("ccd-unit-tests/", folder, "/", name)).string());
    return files;
}

void check_ccd_query_file(const std::string& file)
{
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
        throw Error(str("the CCD query file '", file, "' does not exist (or is not a file)"));
    ccd_query_pair(file);
    read_ccd_queries(file);
}

void ccd_study(const RunContext& run, const std::vector<std::string>& files)
{
    std::cout << "\n== 2. Primitive CCD: the coplanarity cubic (naive) and the inclusion method (conservative)\n"
                 "   on the CCD benchmark's queries; errors against each file's truth\n\n";
    struct Method {
        const char* name;
        CcdResult (*run)(PrimitivePair, const PrimitiveMotion&);
    };
    const Method methods[] = {
        {"cubic (naive)", [](PrimitivePair pair, const PrimitiveMotion& m) { return cubic_ccd(pair, m); }},
        {"inclusion (conservative)",
         [](PrimitivePair pair, const PrimitiveMotion& m) { return inclusion_ccd(pair, m); }},
    };
    Table table("Primitive CCD on the benchmark's queries: collisions reported, errors against the truth, time",
                {{"file", Format::text}, {"method", Format::text}, {"queries", Format::integer},
                 {"collisions", Format::integer}, {"false negatives", Format::integer},
                 {"false positives", Format::integer}, {"median time per query [µs]", Format::fixed, 3},
                 {"mean time per query [µs]", Format::fixed, 3}});
    double sink = 0.0;  // keeps the timed calls from being optimised away
    for (const std::string& file : files) {
        const std::filesystem::path path(file);
        const PrimitivePair pair = ccd_query_pair(path);
        const std::vector<CcdQuery> queries = read_ccd_queries(path);
        const std::string name = (path.parent_path().filename() / path.filename()).generic_string();
        for (const Method& method : methods) {
            int collisions = 0, false_negatives = 0, false_positives = 0;
            std::vector<double> times;
            for (const CcdQuery& query : queries) {
                // One call first (the answer, and how many calls make a batch of about 20 µs, so that
                // the clock's own cost is spread); then the best of batches, per call.
                Timer first;
                const CcdResult result = method.run(pair, query.motion);
                const int calls = int(std::clamp(2e-5 / std::max(first.seconds(), 1e-9), 1.0, 1000.0));
                const double batch = best_time([&] {
                    for (int call = 0; call < calls; ++call)
                        sink += method.run(pair, query.motion).time_of_impact;
                }, 2e-4, 20);
                times.push_back(batch / calls);
                collisions += result.collides;
                false_negatives += query.collides && !result.collides;
                false_positives += !query.collides && result.collides;
            }
            const double mean = std::accumulate(times.begin(), times.end(), 0.0) / double(times.size());
            table.add_row({name, std::string(method.name), double(queries.size()), double(collisions),
                           double(false_negatives), double(false_positives), 1e6 * median(times), 1e6 * mean});
        }
    }
    if (std::isnan(sink))
        std::cout << "unexpected: a time of impact that is NaN\n";
    table.print(std::cout);
    table.write_csv(run.file("ccd_queries_table.csv"));
}

}  // namespace fem::contact::study
