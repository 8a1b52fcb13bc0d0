// Replaced by the analysis stage sources.
