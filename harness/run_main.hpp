// The whole geomint command line as a function (docs/DESIGN.md §4): a user's program registers
// its methods and problems (register_method, register_problem) and returns run_main(argc, argv),
// and is then a full geomint (docs/VERIFY.md "Verify your own integrator"). Returns the exit code.
#pragma once

namespace geomint {
int run_main(int argc, char** argv);
}  // namespace geomint
