"""The README stays true: its test command is exactly what CI runs, its main command reproduces the paper, its
command table lists the commands `nanoimpact` has, it cites the founding paper in full, and its licence is the
one pyproject declares."""
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text()
DOI = "10.1243/17403499JNN101"


def _ci_command():
    lines = [ln for ln in (ROOT / ".ci" / "run").read_text().splitlines()
             if ln and not ln.startswith(("#", "set ", "cd "))]
    assert len(lines) == 1, lines
    return lines[0]


def test_ci_runs_the_readme_test_command_verbatim():
    command = _ci_command()
    assert "pytest" in command
    assert f"```bash\n{command}\n```" in README


def test_readme_main_command_is_the_paper_reproduction():
    main = [ln for ln in README.splitlines() if ln.startswith("python3.11") and "pytest" not in ln]
    assert len(main) == 1
    assert main[0].endswith(".venv/bin/nanoimpact paper")


def test_the_command_table_lists_exactly_the_registered_commands():
    from calibration.cli import registry

    listed = re.findall(r"^\| `nanoimpact (\w+)", README, flags=re.M)
    assert sorted(listed) == sorted(registry())
    assert all(len(row) < 240 for row in README.splitlines() if row.startswith("| `"))     # rows, not paragraphs


def test_the_founding_paper_is_cited_in_full_here_and_in_the_paper_notes():
    for text in (README, (ROOT / "docs" / "paper-notes.md").read_text()):
        assert "Teodorescu" in text and "Rahnejat" in text and "221" in text and "2007" in text and DOI in text


def test_the_licence_file_is_the_one_pyproject_declares():
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["license"]
    declared = declared["text"] if isinstance(declared, dict) else declared
    licence = (ROOT / "LICENSE").read_text()
    assert declared == "MIT" and licence.startswith("MIT License") and "[`LICENSE`](LICENSE)" in README
