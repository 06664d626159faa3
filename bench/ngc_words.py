"""The words of one line of the G-code subset the bench tools read (bench/floor/floor.py,
bench/linuxcnc/compare.py): comments dropped, every other character accounted for, so a typo
is refused instead of being skipped."""
import re

WORD = re.compile(r"([A-Za-z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")


def words_of(text):
    """[(LETTER, value, the value as written)] of one program line, [] for a blank or
    comment-only line. ValueError naming the text when something on it is not a word."""
    clean = re.sub(r"\(.*?\)|;.*", "", text).strip()
    if not clean:
        return []
    words = WORD.findall(clean)
    if "".join(letter + value for letter, value in words) != re.sub(r"\s", "", clean):
        raise ValueError(f"cannot read '{clean}'")
    return [(letter.upper(), float(value), value) for letter, value in words]
