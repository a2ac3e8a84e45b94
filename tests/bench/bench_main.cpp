// main() of every volmorph benchmark: OpenVDB's grid types must be registered before use.
#include <benchmark/benchmark.h>
#include <openvdb/openvdb.h>

int main(int argc, char** argv)
{
    openvdb::initialize();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
