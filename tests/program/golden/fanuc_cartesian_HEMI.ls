/PROG  HEMI
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "waam-slicer";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 22;
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
  ARC Welding Equipment : 1,*,*,*,*;
/MN
   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=1 ;
   3:J P[1] 10% FINE    ;
   4:  Arc Start[1] ;
   5:L P[2] 6mm/sec CNT100    ;
   6:L P[3] 6mm/sec CNT100    ;
   7:L P[4] 6mm/sec CNT100    ;
   8:L P[5] 6mm/sec CNT100    ;
   9:L P[6] 6mm/sec CNT100    ;
  10:L P[7] 6mm/sec CNT100    ;
  11:L P[8] 6mm/sec FINE    ;
  12:  Arc End[1] ;
  13:J P[9] 10% FINE    ;
  14:  Arc Start[1] ;
  15:L P[10] 6mm/sec CNT100    ;
  16:L P[11] 6mm/sec CNT100    ;
  17:L P[12] 6mm/sec CNT100    ;
  18:L P[13] 6mm/sec CNT100    ;
  19:L P[14] 6mm/sec CNT100    ;
  20:L P[15] 6mm/sec CNT100    ;
  21:L P[16] 6mm/sec FINE    ;
  22:  Arc End[1] ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =     0.0000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =   -45.0000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =   -90.0000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =  -135.0000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =  -180.0000 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =   135.0000 deg
};
P[7]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =    90.0000 deg
};
P[8]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     0.0000 deg,	R =    45.0000 deg
};
P[9]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =     6.3662 deg,	R =     0.0000 deg
};
P[10]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =    -4.5109 deg,	P =     4.4969 deg,	R =   -45.1772 deg
};
P[11]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =    -6.3662 deg,	P =     0.0000 deg,	R =   -90.0000 deg
};
P[12]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =    -4.5109 deg,	P =    -4.4969 deg,	R =  -134.8228 deg
};
P[13]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     0.0000 deg,	P =    -6.3662 deg,	R =  -180.0000 deg
};
P[14]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     4.5109 deg,	P =    -4.4969 deg,	R =   134.8228 deg
};
P[15]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     6.3662 deg,	P =     0.0000 deg,	R =    90.0000 deg
};
P[16]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 1',
	X =  1000.747  mm,	Y =  -630.155  mm,	Z =   653.167  mm,
	W =     4.5109 deg,	P =     4.4969 deg,	R =    45.1772 deg
};
/END
