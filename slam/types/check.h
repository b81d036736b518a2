#pragma once

#include <cstdio>
#include <cstdlib>

/// Invariant checks that stay on in every build. A failed check is a bug in slamrig, never bad
/// user input (that is a ConfigError or ParseError at the boundary): it prints file:line and
/// aborts.
#define SLAMRIG_CHECK(cond, msg)                                                               \
  do {                                                                                         \
    if (!(cond)) {                                                                             \
      std::fprintf(stderr, "%s:%d: check failed: %s: %s\n", __FILE__, __LINE__, #cond, (msg)); \
      std::abort();                                                                            \
    }                                                                                          \
  } while (false)

/// Checks that `options.Validate()` found nothing; otherwise prints file:line, `what` (the
/// options' type) and the first broken rule ("particles = 0; must be > 0"), and aborts. For
/// constructors whose callers validate the options at the boundary.
#define SLAMRIG_CHECK_VALID(options, what)                                                    \
  do {                                                                                        \
    const auto slamrig_check_errors = (options).Validate();                                   \
    if (!slamrig_check_errors.empty()) {                                                      \
      std::fprintf(stderr, "%s:%d: check failed: invalid %s: %s\n", __FILE__, __LINE__, what, \
                   slamrig_check_errors.front().c_str());                                     \
      std::abort();                                                                           \
    }                                                                                         \
  } while (false)

/// Like SLAMRIG_CHECK, for hot loops: compiled out unless NDEBUG is unset.
#ifdef NDEBUG
#define SLAMRIG_DCHECK(cond, msg) \
  do {                            \
  } while (false)
#else
#define SLAMRIG_DCHECK(cond, msg) SLAMRIG_CHECK(cond, msg)
#endif
