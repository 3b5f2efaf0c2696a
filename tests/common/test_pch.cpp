// The source of fem_test_pch, which only builds the precompiled header every test target reuses
// (tests/common/CMakeLists.txt).
