// The replica command-line entry point.
#include <platform/cli/app.h>

int main(int argc, char** argv)
{
    return replica::platform::runCli(argc, argv);
}
