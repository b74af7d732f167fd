"""The profiles appmode ships, as data: each file's text (`TEXTS`, what `profile show
--toml` prints) and its TOML as read (`DATA`). Made from the files beside it by
`python -m tests.support.shipped_profiles`: edit those, then run it."""
# ruff: noqa: E501

TEXTS: dict[str, str] = {'sheet': "# The vendor's sheet as the protocol reference reads it (appmode protocol, sections 1–12):\n"
          "# a mecanum/omni car whose A record carries its velocity. appmode's tables of the nine\n"
          "# parameters and of the A record's fields are read from this file.\n"
          'name = "sheet"\n'
          'description = "the vendor\'s sheet: a mecanum/omni car, its velocity in the A record"\n'
          'source = "the vendor\'s protocol sheet (Traditional Chinese), appmode protocol, sections 1–12"\n'
          'baud = 9600\n'
          'period_ms = [50, 50]   # between records, shortest and longest\n'
          'control_port = true    # UART2 takes binary FF FE frames (§8–§12)\n'
          'saves = true           # {Q:W} writes the parameters to flash\n'
          'replies = []           # nothing but records\n'
          'speed_param = "max_speed"  # what the speed keys (+, −) change\n'
          '# One velocity unit in SI (appmode ros, the odometry): mm/s of x and y; of z, π mrad/s\n'
          "# (0.18 °/s: z = 500 turns 90 °/s), the simulated board's turn, which its gyro reports\n"
          'velocity_si = [0.001, 0.0031415926535897933]\n'
          '\n'
          "[pages]                # letters that switch the app's page\n"
          'I = "gravity"\n'
          'J = "joystick"\n'
          'K = "button"\n'
          '\n'
          '[speed_keys]           # letters that change the speed themselves: none\n'
          '\n'
          '[records]\n'
          '# fields: name (JSON key), label (for people), unit, scale (field = scale × value),\n'
          '# signed (as sent), and what it is: motion (grows with the speed) or battery (percent)\n'
          'A = [\n'
          '  { name = "x", label = "x", unit = "velocity unit", motion = true },\n'
          '  { name = "y", label = "y", unit = "velocity unit", motion = true },\n'
          '  { name = "z", label = "z", unit = "velocity unit", motion = true },\n'
          '  { name = "extra", label = "extra", unit = "" },\n'
          ']\n'
          'B = [\n'
          '  { name = "pitch", label = "pitch", unit = "°" },\n'
          '  { name = "roll", label = "roll", unit = "°" },\n'
          '  { name = "yaw", label = "yaw", unit = "°" },\n'
          '  { name = "battery", label = "battery", unit = "%", battery = true, signed = false },\n'
          ']\n'
          '\n'
          '[[params]]\n'
          'name = "max_speed"\n'
          'label = "max speed (velocity unit)"\n'
          'maximum = 65535\n'
          'default = 500\n'
          '\n'
          '[[params]]\n'
          'name = "max_position"\n'
          'label = "position-mode position limit"\n'
          'maximum = 65535\n'
          'default = 10000\n'
          '\n'
          '[[params]]\n'
          'name = "position_kp"\n'
          'label = "position Kp"\n'
          'maximum = 4294967295\n'
          'default = 20\n'
          '\n'
          '[[params]]\n'
          'name = "position_ki"\n'
          'label = "position Ki"\n'
          'maximum = 4294967295\n'
          'default = 0\n'
          '\n'
          '[[params]]\n'
          'name = "position_kd"\n'
          'label = "position Kd"\n'
          'maximum = 4294967295\n'
          'default = 10\n'
          '\n'
          '[[params]]\n'
          'name = "velocity_kp"\n'
          'label = "velocity Kp"\n'
          'maximum = 4294967295\n'
          'default = 10\n'
          '\n'
          '[[params]]\n'
          'name = "velocity_ki"\n'
          'label = "velocity Ki"\n'
          'maximum = 4294967295\n'
          'default = 10\n'
          '\n'
          '[[params]]\n'
          'name = "gyro_compensation"\n'
          'label = "gyro compensation (0.00001)"\n'
          'maximum = 4294967295\n'
          'default = 0\n'
          '\n'
          '[[params]]\n'
          'name = "system_mode"\n'
          'label = "system mode bits"\n'
          'maximum = 65535\n'
          'default = 0\n',
 'minibalance': '# The reference firmware as measured (appmode protocol 13): the mecanum/omni board of the\n'
                "# MiniBalance lineage. Its parameters are the sheet's, with other defaults; its A record\n"
                '# carries magnitudes scaled by 0.7 and the battery.\n'
                'name = "minibalance"\n'
                'description = "the reference mecanum/omni firmware as measured: |0.7x|, |0.7y| and the battery in the A record"\n'
                'source = "a public build of the MiniBalance mecanum/omni firmware (APP_Show, usart3 receive), measured byte by byte: appmode protocol 13"\n'
                'like = "sheet"         # what this file does not say is the sheet\'s\n'
                'period_ms = [60, 90]   # 5·⌈wire time / 5⌉ + 45 ms: 60 for short records, 80 for a C pass\n'
                'saves = false          # {Q:W} is taken and nothing is written\n'
                'defaults = [30, 3000, 40, 0, 40, 10, 10, 0, 0]\n'
                'boot = "mpu_set_sensor complete"  # the sensor\'s messages at power-up (§13.1)\n'
                '\n'
                '[records]\n'
                'A = [\n'
                '  { name = "abs_x", label = "|0.7x|", unit = "velocity unit", scale = 0.7, signed = false, motion = true },\n'
                '  { name = "abs_y", label = "|0.7y|", unit = "velocity unit", scale = 0.7, signed = false, motion = true },\n'
                '  { name = "battery", label = "battery", unit = "%", battery = true },\n'
                '  { name = "extra", label = "extra", unit = "" },\n'
                ']\n'
                "# B as the sheet's, but its battery reads −740 % until the motors are on (§13.1)\n"
                'B = [\n'
                '  { name = "pitch", label = "pitch", unit = "°" },\n'
                '  { name = "roll", label = "roll", unit = "°" },\n'
                '  { name = "yaw", label = "yaw", unit = "°" },\n'
                '  { name = "battery", label = "battery", unit = "%", battery = true },\n'
                ']\n',
 'balance': '# The two-wheel self-balancing car that gave the family its name, as its public STM32\n'
            '# firmware reads and prints the APP port (appmode protocol 14): APP_Show() writes the\n'
            '# records, the USART3 receive handler takes letters and {…} frames.\n'
            'name = "balance"\n'
            'description = "the two-wheel balance car: encoders and the balance angle in the records, its PID gains as parameters"\n'
            'source = "the public MiniBalance two-wheel balance car firmware (STM32): show.c APP_Show(), usart3.c USART3_IRQHandler; appmode protocol 14"\n'
            'baud = 9600\n'
            "period_ms = [50, 150]  # once a pass of the main loop's display step (not measured)\n"
            'control_port = false   # no binary control port\n'
            'saves = true           # {Q:W} writes the gains to flash\n'
            'replies = ["##$"]      # some builds print it before the C record\n'
            '# speed_param: none; its speed is fixed in the firmware (the gains are not a speed)\n'
            '\n'
            '[pages]\n'
            'I = "gravity"\n'
            'J = "joystick"\n'
            'K = "steering"\n'
            '\n'
            '[speed_keys]\n'
            '\n'
            '[records]\n'
            '# A: (u8)|1.1 × right encoder|, |1.1 × left encoder|, battery %, (int)Angle_Balance\n'
            'A = [\n'
            '  { name = "encoder_right", label = "|1.1 right|", unit = "count", scale = 1.1, signed = false, wrap = 256, motion = true },\n'
            '  { name = "encoder_left", label = "|1.1 left|", unit = "count", scale = 1.1, signed = false, motion = true },\n'
            '  { name = "battery", label = "battery", unit = "%", battery = true },\n'
            '  { name = "angle", label = "balance angle", unit = "°" },\n'
            ']\n'
            '# B: (int)Angle_Balance, Encoder_Left, Encoder_Right\n'
            'B = [\n'
            '  { name = "angle", label = "balance angle", unit = "°" },\n'
            '  { name = "encoder_left", label = "left encoder", unit = "count", motion = true },\n'
            '  { name = "encoder_right", label = "right encoder", unit = "count", motion = true },\n'
            ']\n'
            '\n'
            "# {n:v} stores v / 100 (case 0x30: Balance_Kp = Data / 100): the user's 0.42 is the frame's\n"
            '# 42, and the C record prints (int)(Balance_Kp * 100). Defaults as a MiniBalance build sets\n'
            '# them (Balance_Kp=300, Balance_Kd=1, Velocity_Kp=80, Velocity_Ki=0.4); builds differ.\n'
            '# {4:v} … {8:v} are taken and ignored (case 0x34: break): the C record prints 0.\n'
            '[[params]]\n'
            'name = "balance_kp"\n'
            'label = "balance Kp"\n'
            'maximum = 2147483647\n'
            'default = 30000\n'
            'scale = 100\n'
            '\n'
            '[[params]]\n'
            'name = "balance_kd"\n'
            'label = "balance Kd"\n'
            'maximum = 2147483647\n'
            'default = 100\n'
            'scale = 100\n'
            '\n'
            '[[params]]\n'
            'name = "velocity_kp"\n'
            'label = "velocity Kp"\n'
            'maximum = 2147483647\n'
            'default = 8000\n'
            'scale = 100\n'
            '\n'
            '[[params]]\n'
            'name = "velocity_ki"\n'
            'label = "velocity Ki"\n'
            'maximum = 2147483647\n'
            'default = 40\n'
            'scale = 100\n'
            '\n'
            '[[params]]\n'
            'name = "reserved_4"\n'
            'label = "reserved (taken, ignored)"\n'
            'maximum = 0\n'
            'default = 0\n'
            '\n'
            '[[params]]\n'
            'name = "reserved_5"\n'
            'label = "reserved (taken, ignored)"\n'
            'maximum = 0\n'
            'default = 0\n'
            '\n'
            '[[params]]\n'
            'name = "reserved_6"\n'
            'label = "reserved (taken, ignored)"\n'
            'maximum = 0\n'
            'default = 0\n'
            '\n'
            '[[params]]\n'
            'name = "reserved_7"\n'
            'label = "reserved (taken, ignored)"\n'
            'maximum = 0\n'
            'default = 0\n'
            '\n'
            '[[params]]\n'
            'name = "reserved_8"\n'
            'label = "reserved (taken, ignored)"\n'
            'maximum = 0\n'
            'default = 0\n',
 'wheeltec-mec': '# A WHEELTEC ROS car (mini_mec and up): an STM32 board whose chassis port takes the\n'
                 "# vendor's ROS driver's 7B … 7D velocity frames at 115200 bps and streams 24-byte status\n"
                 "# frames at 20 Hz (appmode protocol 15). Its APP port is read as the sheet's.\n"
                 'name = "wheeltec-mec"\n'
                 'description = "a WHEELTEC mecanum ROS car: the chassis port (7B frames), forward, sideways and turn"\n'
                 'source = "the public WHEELTEC ROS drivers (turn_on_wheeltec_robot) and STM32 firmware copies; appmode protocol 15"\n'
                 'like = "sheet"\n'
                 'control_port = false          # no FF FE control port: the chassis port instead\n'
                 'velocity_si = [0.001, 0.001]  # mm/s and mrad/s, as the chassis frames count\n'
                 '\n'
                 '[chassis]\n'
                 'kind = "mec"\n'
                 'timeout_ms = 1000    # F1: zero velocity 1 s after the last valid frame (0: never, as F2)\n'
                 'boot_ms = 10000      # F1: frames ignored, Flag_Stop set, for 1000 ticks at 100 Hz\n'
                 'self_test_ms = 0     # F2, F3: 2000 (a slow drive forward after the boot)\n'
                 'imu_axes = "y,-x,z"  # the IMU chip\'s axes as the status sends them: F1–F4\'s remap\n',
 'wheeltec-akm': '# A WHEELTEC ROS car (mini_akm and up): an STM32 board whose chassis port takes the\n'
                 "# vendor's ROS driver's 7B … 7D velocity frames at 115200 bps and streams 24-byte status\n"
                 "# frames at 20 Hz (appmode protocol 15). Its APP port is read as the sheet's.\n"
                 'name = "wheeltec-akm"\n'
                 'description = "a WHEELTEC Ackermann ROS car: the chassis port (7B frames), steering within a 0.35 m radius"\n'
                 'source = "the public WHEELTEC ROS drivers (turn_on_wheeltec_robot) and STM32 firmware copies; appmode protocol 15"\n'
                 'like = "sheet"\n'
                 'control_port = false          # no FF FE control port: the chassis port instead\n'
                 'velocity_si = [0.001, 0.001]  # mm/s and mrad/s, as the chassis frames count\n'
                 '\n'
                 '[chassis]\n'
                 'kind = "akm"\n'
                 'min_radius = 0.35   # F1: the smallest turning radius, in m\n'
                 'timeout_ms = 1000    # F1: zero velocity 1 s after the last valid frame (0: never, as F2)\n'
                 'boot_ms = 10000      # F1: frames ignored, Flag_Stop set, for 1000 ticks at 100 Hz\n'
                 'self_test_ms = 0     # F2, F3: 2000 (a slow drive forward after the boot)\n'
                 'imu_axes = "y,-x,z"  # the IMU chip\'s axes as the status sends them: F1–F4\'s remap\n',
 'wheeltec-diff': '# A WHEELTEC ROS car (mini_diff, mini_tank, mini_4wd): an STM32 board whose chassis port takes the\n'
                  "# vendor's ROS driver's 7B … 7D velocity frames at 115200 bps and streams 24-byte status\n"
                  "# frames at 20 Hz (appmode protocol 15). Its APP port is read as the sheet's.\n"
                  'name = "wheeltec-diff"\n'
                  'description = "a WHEELTEC differential or tank ROS car: the chassis port (7B frames), forward and turn"\n'
                  'source = "the public WHEELTEC ROS drivers (turn_on_wheeltec_robot) and STM32 firmware copies; appmode protocol 15"\n'
                  'like = "sheet"\n'
                  'control_port = false          # no FF FE control port: the chassis port instead\n'
                  'velocity_si = [0.001, 0.001]  # mm/s and mrad/s, as the chassis frames count\n'
                  '\n'
                  '[chassis]\n'
                  'kind = "diff"\n'
                  'timeout_ms = 1000    # F1: zero velocity 1 s after the last valid frame (0: never, as F2)\n'
                  'boot_ms = 10000      # F1: frames ignored, Flag_Stop set, for 1000 ticks at 100 Hz\n'
                  'self_test_ms = 0     # F2, F3: 2000 (a slow drive forward after the boot)\n'
                  'imu_axes = "y,-x,z"  # the IMU chip\'s axes as the status sends them: F1–F4\'s remap\n'}

DATA: dict[str, dict[str, object]] = {'sheet': {'name': 'sheet',
           'description': "the vendor's sheet: a mecanum/omni car, its velocity in the A record",
           'source': "the vendor's protocol sheet (Traditional Chinese), appmode protocol, sections 1–12",
           'baud': 9600,
           'period_ms': [50, 50],
           'control_port': True,
           'saves': True,
           'replies': [],
           'speed_param': 'max_speed',
           'velocity_si': [0.001, 0.0031415926535897933],
           'pages': {'I': 'gravity', 'J': 'joystick', 'K': 'button'},
           'speed_keys': {},
           'records': {'A': [{'name': 'x', 'label': 'x', 'unit': 'velocity unit', 'motion': True},
                             {'name': 'y', 'label': 'y', 'unit': 'velocity unit', 'motion': True},
                             {'name': 'z', 'label': 'z', 'unit': 'velocity unit', 'motion': True},
                             {'name': 'extra', 'label': 'extra', 'unit': ''}],
                       'B': [{'name': 'pitch', 'label': 'pitch', 'unit': '°'},
                             {'name': 'roll', 'label': 'roll', 'unit': '°'},
                             {'name': 'yaw', 'label': 'yaw', 'unit': '°'},
                             {'name': 'battery', 'label': 'battery', 'unit': '%', 'battery': True, 'signed': False}]},
           'params': [{'name': 'max_speed', 'label': 'max speed (velocity unit)', 'maximum': 65535, 'default': 500},
                      {'name': 'max_position', 'label': 'position-mode position limit', 'maximum': 65535, 'default': 10000},
                      {'name': 'position_kp', 'label': 'position Kp', 'maximum': 4294967295, 'default': 20},
                      {'name': 'position_ki', 'label': 'position Ki', 'maximum': 4294967295, 'default': 0},
                      {'name': 'position_kd', 'label': 'position Kd', 'maximum': 4294967295, 'default': 10},
                      {'name': 'velocity_kp', 'label': 'velocity Kp', 'maximum': 4294967295, 'default': 10},
                      {'name': 'velocity_ki', 'label': 'velocity Ki', 'maximum': 4294967295, 'default': 10},
                      {'name': 'gyro_compensation', 'label': 'gyro compensation (0.00001)', 'maximum': 4294967295, 'default': 0},
                      {'name': 'system_mode', 'label': 'system mode bits', 'maximum': 65535, 'default': 0}]},
 'minibalance': {'name': 'minibalance',
                 'description': 'the reference mecanum/omni firmware as measured: |0.7x|, |0.7y| and the battery in the A record',
                 'source': 'a public build of the MiniBalance mecanum/omni firmware (APP_Show, usart3 receive), measured byte by byte: appmode protocol 13',
                 'like': 'sheet',
                 'period_ms': [60, 90],
                 'saves': False,
                 'defaults': [30, 3000, 40, 0, 40, 10, 10, 0, 0],
                 'boot': 'mpu_set_sensor complete',
                 'records': {'A': [{'name': 'abs_x', 'label': '|0.7x|', 'unit': 'velocity unit', 'scale': 0.7, 'signed': False, 'motion': True},
                                   {'name': 'abs_y', 'label': '|0.7y|', 'unit': 'velocity unit', 'scale': 0.7, 'signed': False, 'motion': True},
                                   {'name': 'battery', 'label': 'battery', 'unit': '%', 'battery': True},
                                   {'name': 'extra', 'label': 'extra', 'unit': ''}],
                             'B': [{'name': 'pitch', 'label': 'pitch', 'unit': '°'},
                                   {'name': 'roll', 'label': 'roll', 'unit': '°'},
                                   {'name': 'yaw', 'label': 'yaw', 'unit': '°'},
                                   {'name': 'battery', 'label': 'battery', 'unit': '%', 'battery': True}]}},
 'balance': {'name': 'balance',
             'description': 'the two-wheel balance car: encoders and the balance angle in the records, its PID gains as parameters',
             'source': 'the public MiniBalance two-wheel balance car firmware (STM32): show.c APP_Show(), usart3.c USART3_IRQHandler; appmode protocol 14',
             'baud': 9600,
             'period_ms': [50, 150],
             'control_port': False,
             'saves': True,
             'replies': ['##$'],
             'pages': {'I': 'gravity', 'J': 'joystick', 'K': 'steering'},
             'speed_keys': {},
             'records': {'A': [{'name': 'encoder_right', 'label': '|1.1 right|', 'unit': 'count', 'scale': 1.1, 'signed': False, 'wrap': 256, 'motion': True},
                               {'name': 'encoder_left', 'label': '|1.1 left|', 'unit': 'count', 'scale': 1.1, 'signed': False, 'motion': True},
                               {'name': 'battery', 'label': 'battery', 'unit': '%', 'battery': True},
                               {'name': 'angle', 'label': 'balance angle', 'unit': '°'}],
                         'B': [{'name': 'angle', 'label': 'balance angle', 'unit': '°'},
                               {'name': 'encoder_left', 'label': 'left encoder', 'unit': 'count', 'motion': True},
                               {'name': 'encoder_right', 'label': 'right encoder', 'unit': 'count', 'motion': True}]},
             'params': [{'name': 'balance_kp', 'label': 'balance Kp', 'maximum': 2147483647, 'default': 30000, 'scale': 100},
                        {'name': 'balance_kd', 'label': 'balance Kd', 'maximum': 2147483647, 'default': 100, 'scale': 100},
                        {'name': 'velocity_kp', 'label': 'velocity Kp', 'maximum': 2147483647, 'default': 8000, 'scale': 100},
                        {'name': 'velocity_ki', 'label': 'velocity Ki', 'maximum': 2147483647, 'default': 40, 'scale': 100},
                        {'name': 'reserved_4', 'label': 'reserved (taken, ignored)', 'maximum': 0, 'default': 0},
                        {'name': 'reserved_5', 'label': 'reserved (taken, ignored)', 'maximum': 0, 'default': 0},
                        {'name': 'reserved_6', 'label': 'reserved (taken, ignored)', 'maximum': 0, 'default': 0},
                        {'name': 'reserved_7', 'label': 'reserved (taken, ignored)', 'maximum': 0, 'default': 0},
                        {'name': 'reserved_8', 'label': 'reserved (taken, ignored)', 'maximum': 0, 'default': 0}]},
 'wheeltec-mec': {'name': 'wheeltec-mec',
                  'description': 'a WHEELTEC mecanum ROS car: the chassis port (7B frames), forward, sideways and turn',
                  'source': 'the public WHEELTEC ROS drivers (turn_on_wheeltec_robot) and STM32 firmware copies; appmode protocol 15',
                  'like': 'sheet',
                  'control_port': False,
                  'velocity_si': [0.001, 0.001],
                  'chassis': {'kind': 'mec', 'timeout_ms': 1000, 'boot_ms': 10000, 'self_test_ms': 0, 'imu_axes': 'y,-x,z'}},
 'wheeltec-akm': {'name': 'wheeltec-akm',
                  'description': 'a WHEELTEC Ackermann ROS car: the chassis port (7B frames), steering within a 0.35 m radius',
                  'source': 'the public WHEELTEC ROS drivers (turn_on_wheeltec_robot) and STM32 firmware copies; appmode protocol 15',
                  'like': 'sheet',
                  'control_port': False,
                  'velocity_si': [0.001, 0.001],
                  'chassis': {'kind': 'akm', 'min_radius': 0.35, 'timeout_ms': 1000, 'boot_ms': 10000, 'self_test_ms': 0, 'imu_axes': 'y,-x,z'}},
 'wheeltec-diff': {'name': 'wheeltec-diff',
                   'description': 'a WHEELTEC differential or tank ROS car: the chassis port (7B frames), forward and turn',
                   'source': 'the public WHEELTEC ROS drivers (turn_on_wheeltec_robot) and STM32 firmware copies; appmode protocol 15',
                   'like': 'sheet',
                   'control_port': False,
                   'velocity_si': [0.001, 0.001],
                   'chassis': {'kind': 'diff', 'timeout_ms': 1000, 'boot_ms': 10000, 'self_test_ms': 0, 'imu_axes': 'y,-x,z'}}}
