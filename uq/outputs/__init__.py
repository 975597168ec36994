"""What reads a finished run: figures, planning answers, report, summary."""
