"""Exceptions with messages meant for users."""


class ScenarioError(ValueError):
    """Bad input: names the file, the key and what is allowed.

    The command line prints ``str(error)`` on one line and exits with status 2.
    """

    def __init__(self, source, key, problem):
        self.source, self.key, self.problem = source, key, problem
        super().__init__(f"{source}: {key}: {problem}" if key else f"{source}: {problem}")
