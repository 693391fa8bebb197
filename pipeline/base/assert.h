// REPLICA_ASSERT: aborts on invariants only a programming error can break (never for input checks).
#pragma once

#include <cstdio>
#include <cstdlib>

#define REPLICA_ASSERT(cond, why)                                                                  \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            std::fprintf(stderr, "%s:%d: assertion '%s' failed: %s\n", __FILE__, __LINE__, #cond,  \
                         why);                                                                     \
            std::abort();                                                                          \
        }                                                                                          \
    } while (false)
