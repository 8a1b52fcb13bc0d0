"""The authors' navigation controller and protocol, piece by piece (SPEC §17.2-17.3; docs/navigation.md,
"The authors' controller").

`bvc3d.navigate(..., policy="authors")` runs the whole controller; these are its parts, for studying it and for
testing it against a transcription of the authors' code: the safety sectors of a scan, the turning rollouts, the
scale mix, the heading rule, one decision, the reliability bookkeeping, and their planner's grid and optimal path.
"""
from ._core import (AuthorsReliability, authors_decide, authors_grid, authors_heading, authors_mix, authors_path,
                    authors_rollouts, sector_minima)

__all__ = ["AuthorsReliability", "authors_decide", "authors_grid", "authors_heading", "authors_mix", "authors_path",
           "authors_rollouts", "sector_minima"]
