"""Characters that only colour-emoji fonts draw, shared by the static output test and the
browser tests.

A notebook's output that uses one of them shows an empty box on a machine without an emoji
font (a fresh Debian or a locked-down lab). Outputs should use marks every font has
(✓ ✗ ○ …) or words.
"""

from __future__ import annotations

import re

#: Code points with default emoji presentation (Unicode's emoji-data), the ranges we meet.
EMOJI = re.compile("[\u231a\u231b\u23e9-\u23ec\u23f0\u23f3\u25fd\u25fe\u2614\u2615\u2648-\u2653"
                   "\u267f\u2693\u26a1\u26aa\u26ab\u26bd\u26be\u26c4\u26c5\u26ce\u26d4\u26ea"
                   "\u26f2\u26f3\u26f5\u26fa\u26fd\u2705\u270a\u270b\u2728\u274c\u274e"
                   "\u2753-\u2755\u2757\u2795-\u2797\u27b0\u27bf\u2b1b\u2b1c\u2b50\u2b55"
                   "\U0001f000-\U0001faff]")


def emoji_in(text: str) -> list[str]:
    """The distinct emoji-only characters of ``text``, sorted."""
    return sorted(set(EMOJI.findall(text)))
