"""Performance benchmarks (``make bench``); targets come from the issues."""
