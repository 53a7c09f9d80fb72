"""The README's set-up contract: two commands first, CI runs the second."""
import re

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


def _blocks(language):
    """The README's fenced code blocks of one language ("" for plain), as text."""
    blocks, current, kind = [], None, None
    for line in (REPO / "README.md").read_text().splitlines():
        if line.lstrip().startswith("```"):
            if current is None:
                current, kind = [], line.strip()[3:]
            else:
                if kind == language:
                    blocks.append("\n".join(current) + "\n")
                current = None
        elif current is not None:
            current.append(line)
    return blocks


def test_readme_python_block_runs(tmp_path, monkeypatch):
    # The API example as a user would paste it: it renders and writes its files.
    (code,) = _blocks("python")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    assert {p.name for p in tmp_path.iterdir()} == {"cornell_box.png", "classic.png"}


def test_readme_command_examples_parse_and_name_real_scenes():
    import rtweekend as rt
    from rtweekend.cli import build_parser
    examples = [line.split("#")[0].split() for block in _blocks("sh")
                for line in block.splitlines() if line.startswith("rtweekend render")]
    assert len(examples) >= 3
    for words in examples:
        args = build_parser().parse_args(words[1:])
        if args.scene and not args.scene.endswith(".toml"):
            assert args.scene in rt.bundled_scenes()


def test_readme_synopsis_options_are_the_commands_options():
    from rtweekend.cli import build_parser
    synopsis = _blocks("")[0]
    documented = set(re.findall(r"(--[a-z-]+|-[a-zA-Z]\b)", synopsis))
    render = build_parser()._subparsers._group_actions[0].choices["render"]
    options = [set(a.option_strings) for a in render._actions
               if a.option_strings and "--help" not in a.option_strings]
    assert all(names & documented for names in options)           # each option shown
    assert documented - {"--version", "--all"} <= set().union(*options)   # and no other


def test_links_in_readme_and_docs_point_at_files():
    for md in [REPO / "README.md", *(REPO / "docs").glob("*.md")]:
        for target in re.findall(r"\]\(([^)#]+?)(?:#[^)]*)?\)", md.read_text()):
            if not target.startswith("http"):
                assert (md.parent / target).exists(), f"{md.name}: {target}"


def _sentences(text):
    return re.split(r"(?<=[.!?])\s+(?=[A-Z`*(])", " ".join(text.split()))


def test_every_speed_figure_in_the_readme_says_which_estimator_and_what_machine():
    # "2.3 M samples/s" alone reads as the default's speed, which draws about a
    # third as many samples: a rate names the estimator it was measured with.
    from rtweekend.options import SAMPLINGS
    readme = (REPO / "README.md").read_text()
    rates = [s for s in _sentences(readme) if re.search(r"[0-9.]+ M samples/s", s)]
    assert rates
    for sentence in rates:
        assert any(f"`{name}`" in sentence for name in SAMPLINGS), sentence
        assert "2-core" in sentence, sentence


def test_the_readme_says_what_rtweekend_does_not_do():
    readme = (REPO / "README.md").read_text()
    limits = readme.split("## Limits", 1)[1].split("\n## ", 1)[0].lower()
    for words in ("environment-map", "gltf", "mitsuba xml", "pbrt", "blender", "gpu",
                  "rotate_y"):
        assert words in limits, words


def test_every_bundled_scene_is_described_in_the_scenes_doc():
    import rtweekend as rt
    doc = (REPO / "docs" / "scenes.md").read_text()
    table = doc.split("## The bundled scenes", 1)[1].split("\n## ", 1)[0]
    for name in rt.bundled_scenes():
        assert f"| `{name}` |" in table, name
