// A tiny return-if-error helper: Abseil 20220623 ships no status macros.
#ifndef NEURALMESH_CORE_STATUS_MACROS_H_
#define NEURALMESH_CORE_STATUS_MACROS_H_

#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

#define NM_STATUS_CONCAT_INNER_(a, b) a##b
#define NM_STATUS_CONCAT_(a, b) NM_STATUS_CONCAT_INNER_(a, b)

// Returns from the current function with the status of `expr` when it is not OK.
#define NM_RETURN_IF_ERROR(expr)                  \
  do {                                            \
    const absl::Status nm_status_ = (expr);       \
    if (!nm_status_.ok()) return nm_status_;      \
  } while (0)

// `NM_ASSIGN_OR_RETURN(auto x, MakeX());` declares x from an OK StatusOr or returns its status.
#define NM_ASSIGN_OR_RETURN(lhs, expr) \
  NM_ASSIGN_OR_RETURN_IMPL_(NM_STATUS_CONCAT_(nm_statusor_, __LINE__), lhs, expr)
#define NM_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                              \
  if (!tmp.ok()) return std::move(tmp).status();  \
  lhs = std::move(tmp).value()

#endif  // NEURALMESH_CORE_STATUS_MACROS_H_
