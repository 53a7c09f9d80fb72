"""The README's set-up contract: two commands first, CI runs the second."""
from conftest import REPO


def _setup_commands():
    lines = (REPO / "README.md").read_text().splitlines()
    start = lines.index("```sh") + 1
    end = lines.index("```", start)
    return lines[start:end], start


def test_readme_opens_with_exactly_two_setup_commands():
    commands, start = _setup_commands()
    assert start < 8, "the set-up commands must come first"
    assert len(commands) == 2
    install_render, install_test = commands
    assert install_render.startswith("pip install .") and "rtweekend render" in install_render
    assert "[test]" in install_test and "pytest" in install_test


def test_ci_runs_the_readme_test_command_verbatim():
    _, install_test = _setup_commands()[0]
    ci = (REPO / ".ci" / "run").read_text().splitlines()
    assert install_test in ci
