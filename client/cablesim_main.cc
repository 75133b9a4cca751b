// The cablesim command line; see client/cli.h.

#include <iostream>

#include "client/cli.h"

int main(int argc, char** argv) { return cablesim::RunCli(argc, argv, std::cout, std::cerr); }
