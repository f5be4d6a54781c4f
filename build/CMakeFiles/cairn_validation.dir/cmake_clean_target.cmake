file(REMOVE_RECURSE
  "libcairn_validation.a"
)
