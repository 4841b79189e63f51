/PROG  HEMI
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "waam-slicer";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 36;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,1,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
  ARC : TRUE ;
  ARC Welding Equipment : 1,*,*,*,*;
/MN
   1:  ! FRAMES: X,Y,Z MM W,P,R DEG ;
   2:  ! UFRAME[0] = WORLD ;
   3:  ! UF0 X,Y=0.000,0.000 ;
   4:  ! UF0 Z,W=0.000,0.000 ;
   5:  ! UF0 P,R=0.000,0.000 ;
   6:  ! UTOOL[1] = TORCH TCP ;
   7:  ! UT1 X,Y=-86.000,0.000 ;
   8:  ! UT1 Z,W=406.000,0.000 ;
   9:  ! UT1 P,R=-36.000,0.000 ;
  10:  UFRAME_NUM=0 ;
  11:  UTOOL_NUM=1 ;
  12:  ! WELD SCHED 1: WFS 10.00 MM/S ;
  13:J P[1] 10% FINE    ;
  14:L P[2] 120cm/min FINE COORD    ;
  15:  Arc Start[1] ;
  16:L P[3] 36cm/min CNT100 COORD    ;
  17:L P[4] 36cm/min CNT100 COORD    ;
  18:L P[5] 36cm/min CNT100 COORD    ;
  19:L P[6] 36cm/min CNT100 COORD    ;
  20:L P[7] 36cm/min CNT100 COORD    ;
  21:L P[8] 36cm/min CNT100 COORD    ;
  22:L P[9] 36cm/min FINE COORD    ;
  23:  Arc End[1] ;
  24:L P[10] 120cm/min FINE COORD    ;
  25:J P[11] 10% FINE    ;
  26:L P[12] 120cm/min FINE COORD    ;
  27:  Arc Start[1] ;
  28:L P[13] 36cm/min CNT100 COORD    ;
  29:L P[14] 36cm/min CNT100 COORD    ;
  30:L P[15] 36cm/min CNT100 COORD    ;
  31:L P[16] 36cm/min CNT100 COORD    ;
  32:L P[17] 36cm/min CNT100 COORD    ;
  33:L P[18] 36cm/min CNT100 COORD    ;
  34:L P[19] 36cm/min FINE COORD    ;
  35:  Arc End[1] ;
  36:L P[20] 120cm/min FINE COORD    ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.4148 deg,	J2=    13.8743 deg,	J3=   -43.2969 deg,
	J4=    53.2973 deg,	J5=   -33.3337 deg,	J6=   -91.8162 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.4222 deg,	J2=    14.5576 deg,	J3=   -44.6050 deg,
	J4=    54.9321 deg,	J5=   -32.5711 deg,	J6=   -93.7704 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,	
	J1=    51.1143 deg,	J2=    13.8746 deg,	J3=   -44.7602 deg,
	J4=    55.0005 deg,	J5=   -33.4672 deg,	J6=   -95.2710 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,	
	J1=    51.9891 deg,	J2=    11.8755 deg,	J3=   -45.2117 deg,
	J4=    55.4716 deg,	J5=   -33.7181 deg,	J6=   -96.5790 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,	
	J1=    51.4823 deg,	J2=     9.6638 deg,	J3=   -45.6461 deg,
	J4=    56.0735 deg,	J5=   -33.1796 deg,	J6=   -96.8677 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.8034 deg,	J2=     8.5789 deg,	J3=   -45.8416 deg,
	J4=    56.5148 deg,	J5=   -32.0964 deg,	J6=   -95.9638 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[7]{
   GP1:
	UF : 0, UT : 1,	
	J1=    47.9959 deg,	J2=     9.3314 deg,	J3=   -45.7373 deg,
	J4=    56.5390 deg,	J5=   -31.1026 deg,	J6=   -94.4711 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[8]{
   GP1:
	UF : 0, UT : 1,	
	J1=    47.2046 deg,	J2=    11.4248 deg,	J3=   -45.3541 deg,
	J4=    56.0606 deg,	J5=   -30.8541 deg,	J6=   -93.2543 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[9]{
   GP1:
	UF : 0, UT : 1,	
	J1=    47.8267 deg,	J2=    13.5674 deg,	J3=   -44.8692 deg,
	J4=    55.3664 deg,	J5=   -31.4900 deg,	J6=   -92.9580 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[10]{
   GP1:
	UF : 0, UT : 1,	
	J1=    47.8192 deg,	J2=    12.8748 deg,	J3=   -43.5484 deg,
	J4=    53.6370 deg,	J5=   -32.2527 deg,	J6=   -90.9156 deg
   GP2:
	UF : 0, UT : 1,	
	J1=     0.1310 deg,	J2=     0.0000 deg
};
P[11]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     6.7959 deg,	J3=   -44.7449 deg,
	J4=    55.5798 deg,	J5=   -33.0295 deg,	J6=   -94.5972 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=   183.7182 deg
};
P[12]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     7.5470 deg,	J3=   -46.1479 deg,
	J4=    57.4063 deg,	J5=   -32.2548 deg,	J6=   -96.7662 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=   183.7182 deg
};
P[13]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     7.5470 deg,	J3=   -46.1479 deg,
	J4=    57.4063 deg,	J5=   -32.2548 deg,	J6=   -96.7662 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=   138.7182 deg
};
P[14]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     7.5470 deg,	J3=   -46.1479 deg,
	J4=    57.4063 deg,	J5=   -32.2548 deg,	J6=   -96.7662 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=    93.7182 deg
};
P[15]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     7.5470 deg,	J3=   -46.1479 deg,
	J4=    57.4063 deg,	J5=   -32.2548 deg,	J6=   -96.7662 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=    48.7182 deg
};
P[16]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     7.5470 deg,	J3=   -46.1479 deg,
	J4=    57.4063 deg,	J5=   -32.2548 deg,	J6=   -96.7662 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=     3.7182 deg
};
P[17]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     7.5470 deg,	J3=   -46.1479 deg,
	J4=    57.4063 deg,	J5=   -32.2548 deg,	J6=   -96.7662 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=   -41.2818 deg
};
P[18]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     7.5470 deg,	J3=   -46.1479 deg,
	J4=    57.4063 deg,	J5=   -32.2548 deg,	J6=   -96.7662 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=   -86.2818 deg
};
P[19]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     7.5470 deg,	J3=   -46.1479 deg,
	J4=    57.4063 deg,	J5=   -32.2548 deg,	J6=   -96.7662 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=  -131.2818 deg
};
P[20]{
   GP1:
	UF : 0, UT : 1,	
	J1=    49.9041 deg,	J2=     6.7959 deg,	J3=   -44.7449 deg,
	J4=    55.5798 deg,	J5=   -33.0295 deg,	J6=   -94.5972 deg
   GP2:
	UF : 0, UT : 1,	
	J1=    -6.2219 deg,	J2=  -131.2818 deg
};
/END
