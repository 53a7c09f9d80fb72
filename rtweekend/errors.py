"""The one exception a user of rtweekend needs to catch for bad input, and how
the description layer builds its one-line messages."""
import functools


class SceneError(ValueError):
    """A scene (file or builder call) or a render option that cannot be used.

    The message is one line naming the file (if any), the object and the field.
    """


class OutputError(SceneError):
    """An image file that cannot be written: its extension, its folder, its
    permissions, its shape.  A SceneError too, so that one except clause still
    catches every bad input."""


class SceneWarning(UserWarning):
    """A scene that renders, but not as its author likely meant (one line)."""


class FieldError(Exception):
    """Internal: a bad value for one field; becomes a SceneError with context."""

    def __init__(self, field, problem):
        super().__init__(f"{field}: {problem}")
        self.field = field
        self.problem = problem


def label(kind, name):
    """How a message names an object: "sphere 'ball'", or "sphere" if unnamed."""
    return f"{kind} '{name}'" if name else kind


def checked(kind):
    """Expose a builder that raises FieldError as one that raises SceneError.

    The loader calls `.raw` instead, to put the file and the position in the
    message itself.
    """
    def wrap(build):
        @functools.wraps(build)
        def public(*args, name=None, **kwargs):
            try:
                return build(*args, name=name, **kwargs)
            except FieldError as e:
                raise SceneError(f"{label(kind, name)}: {e}") from None
        public.raw = build
        public.kind = kind
        return public
    return wrap
