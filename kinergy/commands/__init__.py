"""Sub-commands of the ``kinergy`` command that live in their own modules."""
