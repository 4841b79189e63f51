/PROG  HEMI
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "waam-slicer";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 37;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
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
   6:  ! UTOOL[1] = FLANGE ;
   7:  ! UT1 X,Y=0.000,0.000 ;
   8:  ! UT1 Z,W=0.000,0.000 ;
   9:  ! UT1 P,R=0.000,0.000 ;
  10:  UFRAME_NUM=0 ;
  11:  UTOOL_NUM=1 ;
  12:  ! WELD SCHED 1: WFS 10.00 MM/S ;
  13:  ! TIMED: TORCH SPEED OVER PART ;
  14:J P[1] 10% FINE    ;
  15:L P[2] 1000msec FINE    ;
  16:  Arc Start[1] ;
  17:L P[3] 5891msec CNT100    ;
  18:L P[4] 5891msec CNT100    ;
  19:L P[5] 5891msec CNT100    ;
  20:L P[6] 5891msec CNT100    ;
  21:L P[7] 5891msec CNT100    ;
  22:L P[8] 5891msec CNT100    ;
  23:L P[9] 5891msec FINE    ;
  24:  Arc End[1] ;
  25:L P[10] 1000msec FINE    ;
  26:J P[11] 10% FINE    ;
  27:L P[12] 1000msec FINE    ;
  28:  Arc Start[1] ;
  29:L P[13] 5855msec CNT100    ;
  30:L P[14] 5855msec CNT100    ;
  31:L P[15] 5855msec CNT100    ;
  32:L P[16] 5855msec CNT100    ;
  33:L P[17] 5855msec CNT100    ;
  34:L P[18] 5855msec CNT100    ;
  35:L P[19] 5855msec FINE    ;
  36:  Arc End[1] ;
  37:L P[20] 1000msec FINE    ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   633.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =     0.0000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =     0.0000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =   -45.0000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =   -90.0000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =  -135.0000 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =  -180.0000 deg
};
P[7]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =   135.0000 deg
};
P[8]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =    90.0000 deg
};
P[9]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =    45.0000 deg
};
P[10]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   633.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =    45.0000 deg
};
P[11]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   633.167  mm,
	W =     0.0000 deg,	P =     6.3662 deg,	R =     0.0000 deg
};
P[12]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     6.3662 deg,	R =     0.0000 deg
};
P[13]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =    -4.5109 deg,	P =     4.4969 deg,	R =   -45.1772 deg
};
P[14]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =    -6.3662 deg,	P =     0.0000 deg,	R =   -90.0000 deg
};
P[15]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =    -4.5109 deg,	P =    -4.4969 deg,	R =  -134.8228 deg
};
P[16]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =    -6.3662 deg,	R =  -180.0000 deg
};
P[17]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     4.5109 deg,	P =    -4.4969 deg,	R =   134.8228 deg
};
P[18]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     6.3662 deg,	P =     0.0000 deg,	R =    90.0000 deg
};
P[19]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     4.5109 deg,	P =     4.4969 deg,	R =    45.1772 deg
};
P[20]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   633.167  mm,
	W =     4.5109 deg,	P =     4.4969 deg,	R =    45.1772 deg
};
/END
