// main: the bayeslight command line (cli.cpp does the work); maps failures to exit statuses.
#include "cli.h"

int main(int argc, char** argv) { return bl::run_cli(argc, argv); }
