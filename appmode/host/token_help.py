"""What `appmode send` takes, in words: its help and its errors say the same, and the
command line shows it without loading the parsers."""

APP_TOKENS = (
    "tokens are letters (A–H drive, I J K pages, Z stop; 'JAZ' sends three), frames "
    "({Q:P}, {Q:W}, {0:800}), escaped bytes (\\x01) and waits (wait:0.5)"
)
CONTROL_TOKENS = (
    "tokens are velocity:X,Y,Z (diff-gyro: velocity:LEFT,RIGHT), rotate:DEGREES, "
    "motors:A,B,C[,D], position:X,Y,Z, read:NAME, set:NAME=VALUE, save, load, defaults, "
    "stop, wait:SECONDS and raw hex (FFFE0100000000000000)"
)
CHASSIS_TOKENS = (
    "tokens are velocity:FORWARD,LEFT,TURN (m/s, m/s, rad/s counter-clockwise; held, "
    "sent again every 0.1 s, until the next token that moves or stops), stop, "
    "wait:SECONDS and raw hex (7B00000000000000007B7D; a whole velocity frame holds as "
    "velocity: does)"
)
