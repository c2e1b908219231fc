from pfctl.cli import main

main()
