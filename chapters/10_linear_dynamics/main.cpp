#include "10_linear_dynamics/time_integration.hpp"
#include "common/cli.hpp"
int main(int argc, char** argv)
{
    fem::ChapterCli cli("ch10_linear_dynamics", "10_linear_dynamics", "Chapter 10: linear implicit dynamics");
    return cli.run(argc, argv, [&](const fem::RunContext&) {});
}
