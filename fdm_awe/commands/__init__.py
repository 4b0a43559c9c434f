"""One module per ``fdm-awe`` subcommand (``add_arguments`` + ``run``)."""
