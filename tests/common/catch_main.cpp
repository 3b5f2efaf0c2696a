// The one translation unit that compiles Catch2's main().
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

/// Catch2 2.13 prints a double in fixed notation with 10 decimals, so a failing `x <= 1e-12` read
/// "0.0413 <= 0.0": the bound vanished from the message. 17 decimals show every bound down to
/// 10⁻¹⁷ and the value's digits (trailing zeros dropped).
int main(int argc, char* argv[])
{
    Catch::StringMaker<double>::precision = 17;
    return Catch::Session().run(argc, argv);
}
