"""The library's plumbing, below every analysis: shared names and constants (schema),
argument checks (validate), warnings at the caller's line (warn), old call forms
(deprecation), file writes (atomic), Ctrl-C on the command line (interrupt), the
progress bar (progress), the kernels' instruction-set level (cpu), the result objects'
short summaries (summary), runs of True (runs), and bounded-memory passes over large
arrays and logs (blocks, stream). Private: nothing here is public API."""
