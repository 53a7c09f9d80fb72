"""The one exception a user of rtweekend needs to catch for bad input."""


class SceneError(ValueError):
    """A scene (file or builder call) or a render option that cannot be used.

    The message is one line naming the file (if any), the object and the field.
    """


class FieldError(Exception):
    """Internal: a bad value for one field; becomes a SceneError with context."""

    def __init__(self, field, problem):
        super().__init__(f"{field}: {problem}")
        self.field = field
        self.problem = problem
