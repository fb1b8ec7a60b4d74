from tactileskin.cli import run

run()
