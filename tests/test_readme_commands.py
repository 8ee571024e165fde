"""The README's test command is exactly what CI runs; its main command runs a shipped scene."""
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _ci_command():
    lines = [ln for ln in (ROOT / ".ci" / "run").read_text().splitlines() if ln and not ln.startswith(("#", "set ", "cd "))]
    assert len(lines) == 1, lines
    return lines[0]


def test_ci_runs_the_readme_test_command_verbatim():
    readme = (ROOT / "README.md").read_text()
    command = _ci_command()
    assert "pytest" in command
    assert f"```bash\n{command}\n```" in readme


def test_readme_main_command_is_the_paper_reproduction():
    readme = (ROOT / "README.md").read_text()
    main = [ln for ln in readme.splitlines() if ln.startswith("python3.11") and "pytest" not in ln]
    assert len(main) == 1
    assert main[0].endswith(".venv/bin/nanoimpact paper")
