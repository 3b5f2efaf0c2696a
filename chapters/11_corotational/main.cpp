// ch11_corotational: work in progress (the studies come next).
#include "11_corotational/corotational.hpp"
#include "common/cli.hpp"
int main(int argc, char** argv)
{
    fem::ChapterCli cli("ch11_corotational", "11_corotational", "Chapter 11: corotational elements (work in progress)");
    return cli.run(argc, argv, [&](const fem::RunContext&) {});
}
