"""Reading the user's logs: every log checked for plausibility as it is read (:mod:`.checks`)."""
